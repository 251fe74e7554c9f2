#include "align/light_fit.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include <ceres/ceres.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "align/bundle_adjustment.h"
#include "align/cost_functions/marker_corner_error.h"
#include "align/cost_functions/reprojection_error.h"
#include "core/error.h"

namespace ibrdf {
namespace {

// A light marker seen in one posed photo.
struct LightSighting {
  size_t photo;
  std::array<Eigen::Vector2d, 4> corners;
};

// The light markers' corners in their own frame.
std::array<Eigen::Vector3d, 4> LightMarkerCorners(double size) {
  const double half = 0.5 * size;
  return {Eigen::Vector3d(-half, -half, 0.0), Eigen::Vector3d(half, -half, 0.0), Eigen::Vector3d(half, half, 0.0),
          Eigen::Vector3d(-half, half, 0.0)};
}

// The light fit's problem: the photos' poses and the light markers' poses as Ceres parameter blocks.
class LightProblem {
 public:
  LightProblem(const Camera& camera, const LightTargetsSpec& spec, const std::vector<LightFitPhoto>& photos)
      : intrinsics_(ProjectionIntrinsics(camera)), corners_in_marker_(LightMarkerCorners(spec.size)) {
    for (size_t k = 0; k < photos.size(); ++k) index_[photos[k].photo] = k;
    sightings_.resize(spec.markers.size());
    marker_poses_.resize(spec.markers.size());
    for (size_t m = 0; m < spec.markers.size(); ++m) {
      for (const LightFitPhoto& photo : photos) {
        const auto it = photo.light_markers.find(spec.markers[m].id);
        if (it == photo.light_markers.end()) continue;
        sightings_[m].push_back({photo.photo, it->second});
        if (!cameras_.count(photo.photo)) {
          AngleAxisFromPose(photo.camera_from_world, cameras_[photo.photo].data(), cameras_[photo.photo].data() + 3);
        }
      }
    }
  }

  // Squared corner residuals of one sighting under a marker pose (world_from_marker).
  void SightingCost(const LightSighting& sighting, const double* marker_pose, double* squared) const {
    const double* pose = cameras_.at(sighting.photo).data();
    for (int c = 0; c < 4; ++c) {
      double residual[2];
      MarkerCornerError(intrinsics_, corners_in_marker_[c], sighting.corners[c].x(), sighting.corners[c].y())(
          pose, pose + 3, marker_pose, marker_pose + 3, residual);
      *squared += residual[0] * residual[0] + residual[1] * residual[1];
    }
  }

  // Marker m's start: of IPPE's two solutions in every photo seeing it, the one that best explains all.
  void StartMarker(size_t m, const std::vector<LightFitPhoto>& photos) {
    const cv::Mat camera_matrix = (cv::Mat_<double>(3, 3) << intrinsics_[0], 0, intrinsics_[2] - 0.5, 0, intrinsics_[1],
                                   intrinsics_[3] - 0.5, 0, 0, 1);
    const cv::Mat distortion =
        (cv::Mat_<double>(1, 4) << intrinsics_[4], intrinsics_[5], intrinsics_[6], intrinsics_[7]);
    std::vector<cv::Point3d> object;
    for (const Eigen::Vector3d& c : corners_in_marker_) object.emplace_back(c.x(), c.y(), c.z());
    double best_cost = std::numeric_limits<double>::infinity();
    for (const LightSighting& sighting : sightings_[m]) {
      std::vector<cv::Point2d> pixels;
      for (const Eigen::Vector2d& p : sighting.corners) pixels.emplace_back(p.x() - 0.5, p.y() - 0.5);
      std::vector<cv::Mat> rvecs, tvecs;
      cv::solvePnPGeneric(object, pixels, camera_matrix, distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE);
      for (size_t k = 0; k < rvecs.size(); ++k) {
        const double r[3] = {rvecs[k].at<double>(0), rvecs[k].at<double>(1), rvecs[k].at<double>(2)};
        const double t[3] = {tvecs[k].at<double>(0), tvecs[k].at<double>(1), tvecs[k].at<double>(2)};
        std::array<double, 6> candidate;
        AngleAxisFromPose(photos[index_.at(sighting.photo)].camera_from_world.Inverse() * PoseFromAngleAxis(r, t),
                          candidate.data(), candidate.data() + 3);
        double cost = 0.0;
        for (const LightSighting& other : sightings_[m]) SightingCost(other, candidate.data(), &cost);
        if (cost < best_cost) {
          best_cost = cost;
          marker_poses_[m] = candidate;
        }
      }
    }
  }

  // Adds marker m's corners in every photo that sees it.
  void AddMarker(size_t m, double huber_px) {
    for (const LightSighting& sighting : sightings_[m]) {
      double* pose = cameras_.at(sighting.photo).data();
      for (int c = 0; c < 4; ++c) {
        problem_.AddResidualBlock(MarkerCornerError::Create(intrinsics_, corners_in_marker_[c], sighting.corners[c].x(),
                                                            sighting.corners[c].y()),
                                  new ceres::HuberLoss(huber_px), pose, pose + 3, marker_poses_[m].data(),
                                  marker_poses_[m].data() + 3);
      }
    }
  }

  // Adds the layout's corners seen in the photos of the problem, held constant.
  void AddLayout(const std::vector<LightFitPhoto>& photos, double huber_px) {
    size_t count = 0;
    for (const auto& [i, pose] : cameras_) count += photos[index_.at(i)].layout_corners.size();
    layout_points_.resize(count);
    size_t next_point = 0;
    for (auto& [i, pose] : cameras_) {
      for (const LayoutCorner& corner : photos[index_.at(i)].layout_corners) {
        std::array<double, 3>& point = layout_points_[next_point++];
        point = {corner.p_in_world.x(), corner.p_in_world.y(), corner.p_in_world.z()};
        problem_.AddResidualBlock(ReprojectionError::Create(intrinsics_, corner.pixel.x(), corner.pixel.y()),
                                  new ceres::HuberLoss(huber_px), pose.data(), pose.data() + 3, point.data());
        problem_.SetParameterBlockConstant(point.data());
      }
    }
  }

  // Solves; on failure says why in `*message`.
  bool Solve(double tolerance, std::string* message) {
    if (problem_.NumResidualBlocks() == 0) return true;
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 100;
    options.function_tolerance = tolerance;
    options.parameter_tolerance = tolerance;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem_, &summary);
    *message = summary.message;
    return summary.IsSolutionUsable();
  }

  const std::map<size_t, std::array<double, 6>>& cameras() const { return cameras_; }
  const std::vector<LightSighting>& sightings(size_t m) const { return sightings_[m]; }
  const std::array<double, 6>& marker_pose(size_t m) const { return marker_poses_[m]; }

 private:
  const std::array<double, 8> intrinsics_;
  const std::array<Eigen::Vector3d, 4> corners_in_marker_;
  std::map<size_t, size_t> index_;                     // photo -> its entry in `photos`
  std::map<size_t, std::array<double, 6>> cameras_;    // photo -> camera_from_world (angle-axis, translation)
  std::vector<std::vector<LightSighting>> sightings_;  // per light marker
  std::vector<std::array<double, 6>> marker_poses_;    // per light marker: world_from_marker
  std::vector<std::array<double, 3>> layout_points_;   // constant, addressed by the problem
  ceres::Problem problem_;
};

}  // namespace

bool LightFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(huber_px, 0.0);
  IBRDF_CHECK_OPTION_GT(tolerance, 0.0);
  return true;
}

std::string LightFit::BriefReport() const {
  if (!fitted) return reason.empty() ? "light as given" : reason + "; the light stays as given";
  char buffer[200];
  std::snprintf(buffer, sizeof(buffer), "light at (%.5f, %.5f, %.5f) m from %zu markers (spread %.3f mm)", position.x(),
                position.y(), position.z(), markers.size(), 1e3 * spread_m);
  return buffer;
}

LightFit FitLightToMarkers(const Camera& camera, const LightTargetsSpec& spec, const std::vector<LightFitPhoto>& photos,
                           const LightFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("light fit options", why);
  for (size_t k = 1; k < photos.size(); ++k) {
    IBRDF_CHECK(photos[k - 1].photo < photos[k].photo) << "photos out of order at " << k;
  }
  LightFit fit;
  LightProblem problem(camera, spec, photos);
  for (size_t m = 0; m < spec.markers.size(); ++m) {
    problem.StartMarker(m, photos);
    problem.AddMarker(m, options.huber_px);
  }
  problem.AddLayout(photos, options.huber_px);
  std::string message;
  const bool solved = problem.Solve(options.tolerance, &message);
  if (!solved) {
    fit.reason = "the light markers' refinement failed (" + message + ")";
  } else {
    for (const auto& [i, pose] : problem.cameras()) {
      fit.refined_camera_from_world[i] = PoseFromAngleAxis(pose.data(), pose.data() + 3);
    }
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int estimated = 0;
  for (size_t m = 0; m < spec.markers.size(); ++m) {
    const std::vector<LightSighting>& sightings = problem.sightings(m);
    const std::array<double, 6>& pose = problem.marker_pose(m);
    LightMarkerFit marker;
    marker.id = spec.markers[m].id;
    marker.photos = solved ? static_cast<int>(sightings.size()) : 0;
    if (marker.photos > 0) {
      double squared = 0.0;
      for (const LightSighting& sighting : sightings) problem.SightingCost(sighting, pose.data(), &squared);
      marker.rms_px = std::sqrt(squared / (4.0 * sightings.size()));
      marker.world_from_marker = PoseFromAngleAxis(pose.data(), pose.data() + 3);
      marker.light_in_world = marker.world_from_marker * spec.markers[m].light_in_marker;
      sum += marker.light_in_world;
      ++estimated;
    }
    fit.markers.push_back(marker);
  }
  if (estimated == 0) {
    if (fit.reason.empty()) fit.reason = "no marker of the light was seen in a posed photo";
    return fit;
  }
  fit.fitted = true;
  fit.position = sum / estimated;
  for (const LightMarkerFit& marker : fit.markers) {
    if (marker.photos > 0) fit.spread_m = std::max(fit.spread_m, (marker.light_in_world - fit.position).norm());
  }
  return fit;
}

}  // namespace ibrdf
