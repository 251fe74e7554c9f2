#include "align/bundle_adjustment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "align/cost_functions/marker_corner_error.h"
#include "align/cost_functions/reprojection_error.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"

namespace ibrdf {
namespace {

ceres::Solver::Options SolverOptions(int parameters, int max_iterations, double tolerance) {
  ceres::Solver::Options options;
  // Small problems (one photo, a few dozen photos and markers) solve fastest dense; large ones sparse.
  options.linear_solver_type = parameters <= 1200 ? ceres::DENSE_QR : ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = tolerance;
  options.parameter_tolerance = tolerance;
  return options;
}

// OpenCV's view of the camera (pixel centres at 0, not 0.5).
struct OpenCvCamera {
  explicit OpenCvCamera(const std::array<double, 8>& k)
      : matrix((cv::Mat_<double>(3, 3) << k[0], 0, k[2] - 0.5, 0, k[1], k[3] - 0.5, 0, 0, 1)),
        distortion((cv::Mat_<double>(1, 4) << k[4], k[5], k[6], k[7])) {}
  cv::Mat matrix, distortion;
};

Rigid3d PoseFromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  const double r[3] = {rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)};
  const double t[3] = {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
  return PoseFromAngleAxis(r, t);
}

// The inlier corners of posed markers in one photo: world points and pixels.
void UsableCorners(const BundleImage& image, const std::map<int, BundleMarker>& markers,
                   std::vector<Eigen::Vector3d>* points, std::vector<Eigen::Vector2d>* pixels) {
  points->clear();
  pixels->clear();
  for (const CornerObservation& o : image.corners) {
    const auto it = markers.find(o.marker_id);
    if (!o.inlier || it == markers.end() || !it->second.posed) continue;
    points->push_back(it->second.corners[o.corner]);
    pixels->push_back(o.pixel);
  }
}

double SquaredResidual(const std::array<double, 8>& intrinsics, const double* pose, const Eigen::Vector3d& point,
                       const Eigen::Vector2d& pixel) {
  const double p[3] = {point.x(), point.y(), point.z()};
  double residual[2];
  ReprojectionError(intrinsics, pixel.x(), pixel.y())(pose, pose + 3, p, residual);
  return residual[0] * residual[0] + residual[1] * residual[1];
}

// One photo's pose against constant points (Huber). False when Ceres fails.
bool RefinePose(const std::array<double, 8>& intrinsics, const std::vector<Eigen::Vector3d>& points,
                const std::vector<Eigen::Vector2d>& pixels, double huber_px, Rigid3d* camera_from_world) {
  std::array<double, 6> pose;
  AngleAxisFromPose(*camera_from_world, pose.data(), pose.data() + 3);
  std::vector<std::array<double, 3>> constants(points.size());
  ceres::Problem problem;
  for (size_t k = 0; k < points.size(); ++k) {
    constants[k] = {points[k].x(), points[k].y(), points[k].z()};
    problem.AddResidualBlock(ReprojectionError::Create(intrinsics, pixels[k].x(), pixels[k].y()),
                             new ceres::HuberLoss(huber_px), pose.data(), pose.data() + 3, constants[k].data());
    problem.SetParameterBlockConstant(constants[k].data());
  }
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(6, 100, 1e-12), &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  *camera_from_world = PoseFromAngleAxis(pose.data(), pose.data() + 3);
  return true;
}

double PoseRms(const std::array<double, 8>& intrinsics, const Rigid3d& camera_from_world,
               const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector2d>& pixels) {
  double pose[6];
  AngleAxisFromPose(camera_from_world, pose, pose + 3);
  double squared = 0.0;
  for (size_t k = 0; k < points.size(); ++k) squared += SquaredResidual(intrinsics, pose, points[k], pixels[k]);
  return points.empty() ? 0.0 : std::sqrt(squared / points.size());
}

// A photo's first pose from its posed markers: SQPnP, then the robust refinement.
bool InitialImagePose(const std::array<double, 8>& intrinsics, const OpenCvCamera& cv_camera, double huber_px,
                      const BundleImage& image, const std::map<int, BundleMarker>& markers,
                      Rigid3d* camera_from_world) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  UsableCorners(image, markers, &points, &pixels);
  if (points.size() < 4) return false;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image_points;
  for (size_t k = 0; k < points.size(); ++k) {
    object.emplace_back(points[k].x(), points[k].y(), points[k].z());
    image_points.emplace_back(pixels[k].x() - 0.5, pixels[k].y() - 0.5);
  }
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, image_points, cv_camera.matrix, cv_camera.distortion, rvec, tvec, false,
                    cv::SOLVEPNP_SQPNP)) {
    return false;
  }
  *camera_from_world = PoseFromCv(rvec, tvec);
  return RefinePose(intrinsics, points, pixels, huber_px, camera_from_world);
}

// A free marker's first pose from the posed photos that see it: both of IPPE's square solutions in every
// such photo, the candidate that best explains all of them.
bool InitialMarkerPose(const std::array<double, 8>& intrinsics, const OpenCvCamera& cv_camera,
                       const std::vector<BundleImage>& images, BundleMarker* marker) {
  struct Sighting {
    const BundleImage* image;
    std::array<Eigen::Vector2d, 4> pixels;
    int seen = 0;  // corners observed
  };
  std::vector<Sighting> sightings;
  for (const BundleImage& image : images) {
    if (!image.posed) continue;
    Sighting sighting{&image, {}, 0};
    for (const CornerObservation& o : image.corners) {
      if (o.marker_id != marker->id) continue;
      sighting.pixels[o.corner] = o.pixel;
      ++sighting.seen;
    }
    if (sighting.seen == 4) sightings.push_back(sighting);
  }
  if (sightings.empty()) return false;
  const std::array<Eigen::Vector3d, 4> in_marker = MarkerCornersInMarker(marker->size);
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& c : in_marker) object.emplace_back(c.x(), c.y(), c.z());
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Sighting& sighting : sightings) {
    std::vector<cv::Point2d> pixels;
    for (const Eigen::Vector2d& p : sighting.pixels) pixels.emplace_back(p.x() - 0.5, p.y() - 0.5);
    std::vector<cv::Mat> rvecs, tvecs;
    cv::solvePnPGeneric(object, pixels, cv_camera.matrix, cv_camera.distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE);
    for (size_t k = 0; k < rvecs.size(); ++k) {
      const Rigid3d candidate = sighting.image->camera_from_world.Inverse() * PoseFromCv(rvecs[k], tvecs[k]);
      double cost = 0.0;
      for (const Sighting& other : sightings) {
        double pose[6];
        AngleAxisFromPose(other.image->camera_from_world, pose, pose + 3);
        for (int c = 0; c < 4; ++c)
          cost += SquaredResidual(intrinsics, pose, candidate * in_marker[c], other.pixels[c]);
      }
      if (cost < best_cost) {
        best_cost = cost;
        marker->world_from_marker = candidate;
      }
    }
  }
  if (!std::isfinite(best_cost)) return false;
  marker->posed = true;
  marker->UpdateCorners();
  return true;
}

}  // namespace

std::array<double, 8> ProjectionIntrinsics(const Camera& camera) {
  std::array<double, 8> k = {camera.FocalX(), camera.FocalY(), camera.PrincipalX(), camera.PrincipalY(), 0, 0, 0, 0};
  const std::vector<double>& p = camera.params;
  switch (camera.model) {
    case CameraModelId::kSimpleRadial:
      k[4] = p[3];
      break;
    case CameraModelId::kRadial:
      k[4] = p[3];
      k[5] = p[4];
      break;
    case CameraModelId::kOpenCV:
      k[4] = p[4];
      k[5] = p[5];
      k[6] = p[6];
      k[7] = p[7];
      break;
    default:
      break;
  }
  return k;
}

void AngleAxisFromPose(const Rigid3d& pose, double* rotation, double* translation) {
  const Eigen::Matrix3d r = pose.rotation.toRotationMatrix();
  double matrix[9];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) matrix[col * 3 + row] = r(row, col);
  }
  ceres::RotationMatrixToAngleAxis(matrix, rotation);
  for (int k = 0; k < 3; ++k) translation[k] = pose.translation[k];
}

Rigid3d PoseFromAngleAxis(const double* rotation, const double* translation) {
  double matrix[9];
  ceres::AngleAxisToRotationMatrix(rotation, matrix);  // column-major
  Eigen::Matrix3d r;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r(row, col) = matrix[col * 3 + row];
  }
  return Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d(translation[0], translation[1], translation[2]));
}

std::array<Eigen::Vector3d, 4> MarkerCornersInMarker(double size) {
  const double h = 0.5 * size;
  return {Eigen::Vector3d(-h, -h, 0.0), Eigen::Vector3d(h, -h, 0.0), Eigen::Vector3d(h, h, 0.0),
          Eigen::Vector3d(-h, h, 0.0)};
}

void BundleMarker::UpdateCorners() {
  if (fixed) return;
  const std::array<Eigen::Vector3d, 4> in_marker = MarkerCornersInMarker(size);
  for (int c = 0; c < 4; ++c) corners[c] = world_from_marker * in_marker[c];
}

bool BundleAdjustmentOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(huber_px, 0.0);
  IBRDF_CHECK_OPTION_GE(max_num_iterations, 1);
  IBRDF_CHECK_OPTION_GT(tolerance, 0.0);
  IBRDF_CHECK_OPTION_GT(min_outlier_px, 0.0);
  return true;
}

std::string BundleAdjustmentSummary::BriefReport() const {
  char buffer[320];
  if (!success) {
    std::snprintf(buffer, sizeof(buffer), "bundle adjustment failed: %s", message.c_str());
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer),
                "bundle adjustment: %d photos, %d free and %d fixed markers, %d corners (%d outliers left out), "
                "RMS %.3f -> %.3f px in %d iterations, %.2f s",
                images, free_markers, fixed_markers, corners, outliers, initial_rms_px, final_rms_px, iterations,
                total_s);
  return buffer;
}

namespace {

// The bundle adjustment's parameters as Ceres blocks: the posed photos' poses, the free markers' poses
// and the fixed markers' corners, over the photos and markers it adjusts.
class BundleParameters {
 public:
  BundleParameters(const Camera& camera, std::vector<BundleImage>* images, std::map<int, BundleMarker>* markers)
      : intrinsics_(ProjectionIntrinsics(camera)), images_(images), markers_(markers), camera_poses_(images->size()) {
    for (size_t i = 0; i < images->size(); ++i) {
      if ((*images)[i].posed)
        AngleAxisFromPose((*images)[i].camera_from_world, camera_poses_[i].data(), camera_poses_[i].data() + 3);
    }
    for (auto& [id, marker] : *markers) {
      if (!marker.posed) continue;
      if (marker.fixed) {
        for (int c = 0; c < 4; ++c)
          fixed_points_[id][c] = {marker.corners[c].x(), marker.corners[c].y(), marker.corners[c].z()};
      } else {
        AngleAxisFromPose(marker.world_from_marker, marker_poses_[id].data(), marker_poses_[id].data() + 3);
      }
    }
  }

  // A corner of a posed marker.
  bool Usable(const CornerObservation& o) const {
    const auto it = markers_->find(o.marker_id);
    return it != markers_->end() && it->second.posed;
  }

  // A corner's residual under the current parameters.
  void Residual(size_t i, const CornerObservation& o, double* r) const {
    const BundleMarker& marker = markers_->at(o.marker_id);
    const double* pose = camera_poses_[i].data();
    if (marker.fixed) {
      ReprojectionError(intrinsics_, o.pixel.x(), o.pixel.y())(pose, pose + 3,
                                                               fixed_points_.at(o.marker_id)[o.corner].data(), r);
    } else {
      const double* m = marker_poses_.at(o.marker_id).data();
      MarkerCornerError(intrinsics_, MarkerCornersInMarker(marker.size)[o.corner], o.pixel.x(), o.pixel.y())(
          pose, pose + 3, m, m + 3, r);
    }
  }

  // The RMS over the inlier corners of posed photos.
  double InlierRms() const {
    double squared = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < images_->size(); ++i) {
      if (!(*images_)[i].posed) continue;
      for (const CornerObservation& o : (*images_)[i].corners) {
        if (!o.inlier || !Usable(o)) continue;
        double r[2];
        Residual(i, o, r);
        squared += r[0] * r[0] + r[1] * r[1];
        ++count;
      }
    }
    return count ? std::sqrt(squared / count) : 0.0;
  }

  // One solve over the inlier corners of posed photos (Huber loss), fixed corners constant. False,
  // with summary->message, when no fixed marker is seen or Ceres finds no usable solution.
  bool Solve(const BundleAdjustmentOptions& options, BundleAdjustmentSummary* summary) {
    ceres::Problem problem;
    std::set<int> fixed_seen, free_seen;
    for (size_t i = 0; i < images_->size(); ++i) {
      BundleImage& image = (*images_)[i];
      if (!image.posed) continue;
      double* pose = camera_poses_[i].data();
      for (const CornerObservation& o : image.corners) {
        if (!o.inlier || !Usable(o)) continue;
        const BundleMarker& marker = markers_->at(o.marker_id);
        if (marker.fixed) {
          double* point = fixed_points_.at(o.marker_id)[o.corner].data();
          problem.AddResidualBlock(ReprojectionError::Create(intrinsics_, o.pixel.x(), o.pixel.y()),
                                   new ceres::HuberLoss(options.huber_px), pose, pose + 3, point);
          problem.SetParameterBlockConstant(point);
          fixed_seen.insert(o.marker_id);
        } else {
          double* m = marker_poses_.at(o.marker_id).data();
          problem.AddResidualBlock(MarkerCornerError::Create(intrinsics_, MarkerCornersInMarker(marker.size)[o.corner],
                                                             o.pixel.x(), o.pixel.y()),
                                   new ceres::HuberLoss(options.huber_px), pose, pose + 3, m, m + 3);
          free_seen.insert(o.marker_id);
        }
      }
    }
    if (fixed_seen.empty()) {
      summary->message = "no marker of fixed layout is seen by a posed photo: the gauge is free";
      return false;
    }
    const int parameters = 6 * static_cast<int>(std::count_if(images_->begin(), images_->end(),
                                                              [](const BundleImage& b) { return b.posed; })) +
                           6 * static_cast<int>(free_seen.size());
    ceres::Solver::Summary solver_summary;
    ceres::Solve(SolverOptions(parameters, options.max_num_iterations, options.tolerance), &problem, &solver_summary);
    summary->iterations += static_cast<int>(solver_summary.iterations.size());
    if (!solver_summary.IsSolutionUsable()) {
      summary->message = solver_summary.message;
      return false;
    }
    summary->fixed_markers = static_cast<int>(fixed_seen.size());
    summary->free_markers = static_cast<int>(free_seen.size());
    return true;
  }

  // The outlier pass: per photo, corners beyond max(min_outlier_px, 3 robust sigmas). A corner beyond
  // the limit condemns its marker in this photo: its corners come from lines fitted to its sides, and a
  // partly hidden side shifts both of that side's corners.
  void MarkOutliers(double min_outlier_px) {
    for (size_t i = 0; i < images_->size(); ++i) {
      BundleImage& image = (*images_)[i];
      if (!image.posed) continue;
      std::vector<double> norms;
      for (const CornerObservation& o : image.corners) {
        if (!o.inlier || !Usable(o)) continue;
        double r[2];
        Residual(i, o, r);
        norms.push_back(std::hypot(r[0], r[1]));
      }
      if (norms.empty()) continue;
      const double limit = std::max(min_outlier_px, 3.0 * 1.4826 * Median(norms));
      size_t k = 0;
      std::set<int> condemned;
      for (const CornerObservation& o : image.corners) {
        if (!o.inlier || !Usable(o)) continue;
        if (norms[k++] > limit) condemned.insert(o.marker_id);
      }
      for (CornerObservation& o : image.corners) {
        if (condemned.count(o.marker_id)) o.inlier = false;
      }
    }
  }

  // Writes the poses back, and the residuals per photo and per marker.
  void WriteBack(BundleAdjustmentSummary* summary) {
    for (auto& [id, pose] : marker_poses_) {
      BundleMarker& marker = markers_->at(id);
      marker.world_from_marker = PoseFromAngleAxis(pose.data(), pose.data() + 3);
      marker.UpdateCorners();
    }
    std::map<int, std::pair<int, double>> marker_sums;
    std::map<int, std::set<size_t>> marker_images;
    double all_squared = 0.0;
    for (size_t i = 0; i < images_->size(); ++i) {
      BundleImage& image = (*images_)[i];
      if (!image.posed) continue;
      image.camera_from_world = PoseFromAngleAxis(camera_poses_[i].data(), camera_poses_[i].data() + 3);
      double squared = 0.0;
      image.inliers = image.outliers = 0;
      for (const CornerObservation& o : image.corners) {
        if (!Usable(o)) continue;
        if (!o.inlier) {
          ++image.outliers;
          continue;
        }
        double r[2];
        Residual(i, o, r);
        const double r2 = r[0] * r[0] + r[1] * r[1];
        squared += r2;
        ++image.inliers;
        ++marker_sums[o.marker_id].first;
        marker_sums[o.marker_id].second += r2;
        marker_images[o.marker_id].insert(i);
      }
      image.rms_px = image.inliers ? std::sqrt(squared / image.inliers) : 0.0;
      all_squared += squared;
      summary->corners += image.inliers;
      summary->outliers += image.outliers;
      ++summary->images;
    }
    for (auto& [id, marker] : *markers_) {
      const auto it = marker_sums.find(id);
      marker.images = it == marker_sums.end() ? 0 : static_cast<int>(marker_images[id].size());
      marker.rms_px = it == marker_sums.end() ? 0.0 : std::sqrt(it->second.second / it->second.first);
    }
    summary->final_rms_px = summary->corners ? std::sqrt(all_squared / summary->corners) : 0.0;
  }

 private:
  const std::array<double, 8> intrinsics_;
  std::vector<BundleImage>* images_;
  std::map<int, BundleMarker>* markers_;
  std::vector<std::array<double, 6>> camera_poses_;
  std::map<int, std::array<double, 6>> marker_poses_;
  std::map<int, std::array<std::array<double, 3>, 4>> fixed_points_;
};

}  // namespace

BundleAdjustmentSummary BundleAdjust(const Camera& camera, const BundleAdjustmentOptions& options,
                                     std::vector<BundleImage>* images, std::map<int, BundleMarker>* markers) {
  Timer timer;
  BundleAdjustmentSummary summary;
  BundleParameters parameters(camera, images, markers);
  summary.initial_rms_px = parameters.InlierRms();
  for (int solve = 0; solve < 2; ++solve) {
    if (!parameters.Solve(options, &summary)) {
      summary.total_s = timer.ElapsedSeconds();
      return summary;
    }
    if (solve == 0) parameters.MarkOutliers(options.min_outlier_px);
  }
  parameters.WriteBack(&summary);
  summary.total_s = timer.ElapsedSeconds();
  summary.success = true;
  return summary;
}

int InitializeByChaining(const Camera& camera, double huber_px, std::vector<BundleImage>* images,
                         std::map<int, BundleMarker>* markers) {
  const std::array<double, 8> intrinsics = ProjectionIntrinsics(camera);
  const OpenCvCamera cv_camera(intrinsics);
  int posed_images = 0;
  std::vector<bool> failed(images->size(), false);
  // Posed markers a photo sees (all four corners detected).
  auto posed_markers_seen = [&](const BundleImage& image) {
    std::map<int, int> corners;
    for (const CornerObservation& o : image.corners) {
      const auto it = markers->find(o.marker_id);
      if (it != markers->end() && it->second.posed) ++corners[o.marker_id];
    }
    return static_cast<int>(std::count_if(corners.begin(), corners.end(), [](const auto& c) { return c.second == 4; }));
  };
  for (;;) {
    bool progress = false;
    // The unposed photo that sees the most posed markers, one at a time, so the photos with the most
    // support come first; then every free marker the posed photos see.
    int best = -1, best_count = 0;
    for (size_t i = 0; i < images->size(); ++i) {
      if ((*images)[i].posed || failed[i]) continue;
      const int count = posed_markers_seen((*images)[i]);
      if (count > best_count) {
        best = static_cast<int>(i);
        best_count = count;
      }
    }
    if (best >= 0) {
      BundleImage& image = (*images)[best];
      if (InitialImagePose(intrinsics, cv_camera, huber_px, image, *markers, &image.camera_from_world)) {
        image.posed = true;
        ++posed_images;
      } else {
        failed[best] = true;
      }
      progress = true;
    }
    for (auto& [id, marker] : *markers) {
      if (marker.posed || marker.fixed) continue;
      if (InitialMarkerPose(intrinsics, cv_camera, *images, &marker)) progress = true;
    }
    if (!progress) break;
  }
  return posed_images;
}

PoseUncertainty EstimatePoseUncertainty(const Camera& camera, const BundleImage& image,
                                        const std::map<int, BundleMarker>& markers, double pixel_sigma) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  UsableCorners(image, markers, &points, &pixels);
  PoseUncertainty uncertainty;
  uncertainty.position_sigma_m = uncertainty.rotation_sigma_deg = std::numeric_limits<double>::infinity();
  if (points.size() < 3) return uncertainty;
  // Parameters: the camera's centre (metres) and a small rotation of the camera in the world (radians).
  const Rigid3d world_from_camera = image.camera_from_world.Inverse();
  auto project = [&](const Eigen::Matrix<double, 6, 1>& delta, Eigen::VectorXd* out) {
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(
        delta.tail<3>().norm(),
        delta.tail<3>().norm() > 0.0 ? Eigen::Vector3d(delta.tail<3>().normalized()) : Eigen::Vector3d::UnitZ()));
    const Rigid3d perturbed(turn * world_from_camera.rotation, world_from_camera.translation + delta.head<3>());
    const Rigid3d camera_from_world = perturbed.Inverse();
    out->resize(2 * points.size());
    for (size_t k = 0; k < points.size(); ++k)
      out->segment<2>(2 * k) = camera.ImageFromCamera(camera_from_world * points[k]);
  };
  Eigen::MatrixXd jacobian(2 * points.size(), 6);
  const double step = 1e-6;
  for (int p = 0; p < 6; ++p) {
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::VectorXd plus, minus;
    delta[p] = step;
    project(delta, &plus);
    delta[p] = -step;
    project(delta, &minus);
    jacobian.col(p) = (plus - minus) / (2.0 * step);
  }
  const Eigen::Matrix<double, 6, 6> normal = jacobian.transpose() * jacobian;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(normal);
  if (!(eigen.eigenvalues().minCoeff() > 1e-12 * std::max(1.0, eigen.eigenvalues().maxCoeff()))) return uncertainty;
  const Eigen::Matrix<double, 6, 6> covariance = pixel_sigma * pixel_sigma * normal.inverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> position(covariance.topLeftCorner<3, 3>());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rotation(covariance.bottomRightCorner<3, 3>());
  uncertainty.position_sigma_m = std::sqrt(std::max(0.0, position.eigenvalues().maxCoeff()));
  uncertainty.rotation_sigma_deg = std::sqrt(std::max(0.0, rotation.eigenvalues().maxCoeff())) / kDegree;
  return uncertainty;
}

double AlternativePoseRms(const Camera& camera, const BundleImage& image, const std::map<int, BundleMarker>& markers,
                          double huber_px, Rigid3d* alternative) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  UsableCorners(image, markers, &points, &pixels);
  if (points.size() < 4) return -1.0;
  // Coplanar: the smallest spread across the points' best plane is tiny next to the largest.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= points.size();
  Eigen::MatrixXd centred(points.size(), 3);
  for (size_t k = 0; k < points.size(); ++k) centred.row(k) = (points[k] - mean).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred);
  if (!(svd.singularValues()[2] < 1e-3 * svd.singularValues()[0])) return -1.0;
  const std::array<double, 8> intrinsics = ProjectionIntrinsics(camera);
  const OpenCvCamera cv_camera(intrinsics);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image_points;
  for (size_t k = 0; k < points.size(); ++k) {
    object.emplace_back(points[k].x(), points[k].y(), points[k].z());
    image_points.emplace_back(pixels[k].x() - 0.5, pixels[k].y() - 0.5);
  }
  std::vector<cv::Mat> rvecs, tvecs;
  try {
    cv::solvePnPGeneric(object, image_points, cv_camera.matrix, cv_camera.distortion, rvecs, tvecs, false,
                        cv::SOLVEPNP_IPPE);
  } catch (const cv::Exception&) {
    return -1.0;
  }
  double farthest = -1.0;
  for (size_t k = 0; k < rvecs.size(); ++k) {
    const Rigid3d candidate = PoseFromCv(rvecs[k], tvecs[k]);
    const double angle = candidate.rotation.angularDistance(image.camera_from_world.rotation);
    if (angle > farthest) {
      farthest = angle;
      *alternative = candidate;
    }
  }
  if (farthest < 0.0) return -1.0;
  if (!RefinePose(intrinsics, points, pixels, huber_px, alternative)) return -1.0;
  // The refinement fell back to the photo's own pose: there is no second minimum.
  if (alternative->rotation.angularDistance(image.camera_from_world.rotation) < 0.5 * kDegree) return -1.0;
  return PoseRms(intrinsics, *alternative, points, pixels);
}

}  // namespace ibrdf
