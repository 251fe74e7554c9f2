#include "align/white_reference_pose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/logging.h"
#include "radiometry/linear_image.h"

namespace ibrdf {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// A small motion of an object frame: object_from_moved = (translation, rotation vector).
Rigid3d SmallMotion(const Eigen::Matrix<double, 6, 1>& delta) {
  const Eigen::Vector3d w = delta.tail<3>();
  const Eigen::Quaterniond turn(w.norm() > 0.0 ? Eigen::AngleAxisd(w.norm(), w.normalized())
                                               : Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ()));
  return Rigid3d(turn, delta.head<3>());
}

// The covariance of delta in camera_from_object x SmallMotion(delta) from the inlier corners of fixed
// markers in `image` (points in the object frame), for corner noise `sigma_px`: sigma^2 (J^T J)^-1,
// J by central differences. Infinite where the corners do not determine the pose.
Matrix6d PoseCovariance(const Camera& camera, const BundleImage& image, const std::map<int, BundleMarker>& markers,
                        double sigma_px) {
  std::vector<Eigen::Vector3d> points;
  for (const CornerObservation& o : image.corners) {
    const auto it = markers.find(o.marker_id);
    if (o.inlier && it != markers.end() && it->second.posed) points.push_back(it->second.corners[o.corner]);
  }
  Eigen::MatrixXd jacobian(2 * points.size(), 6);
  const double step[2] = {1e-6, 1e-6};  // metres, radians
  for (int j = 0; j < 6; ++j) {
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    delta[j] = step[j / 3];
    const Rigid3d plus = image.camera_from_world * SmallMotion(delta);
    const Rigid3d minus = image.camera_from_world * SmallMotion(-delta);
    for (size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector2d d = camera.ImageFromCamera(plus * points[k]) - camera.ImageFromCamera(minus * points[k]);
      jacobian.block<2, 1>(2 * k, j) = d / (2.0 * delta[j]);
    }
  }
  const Matrix6d normal = jacobian.transpose() * jacobian;
  Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(normal);
  if (points.size() < 4 || !(eigen.eigenvalues()[0] > 1e-9 * eigen.eigenvalues()[5])) {
    return Matrix6d::Constant(std::numeric_limits<double>::infinity());
  }
  return sigma_px * sigma_px * normal.inverse();
}

// Corners of the ids in `markers` detected in a photo, as a bundle image.
BundleImage ImageOf(const std::vector<MarkerDetection>& detections, const std::map<int, BundleMarker>& markers,
                    int* count) {
  BundleImage image;
  *count = 0;
  for (const MarkerDetection& d : detections) {
    const auto it = markers.find(d.id);
    if (it == markers.end() || !it->second.posed) continue;
    ++*count;
    for (int k = 0; k < 4; ++k) image.corners.push_back({d.id, k, d.corners[k], true});
  }
  return image;
}

// Poses one photo against fixed markers: chaining's PnP start and the robust refinement with its
// outlier pass. False (with `why`) when it cannot.
bool PoseAgainst(const Camera& camera, const WhiteReferencePoseOptions& options, std::map<int, BundleMarker> markers,
                 BundleImage* image, std::string* why) {
  std::vector<BundleImage> images{*image};
  if (InitializeByChaining(camera, options.huber_px, &images, &markers) != 1) {
    *why = "no PnP pose";
    return false;
  }
  BundleAdjustmentOptions bundle;
  bundle.huber_px = options.huber_px;
  const BundleAdjustmentSummary summary = BundleAdjust(camera, bundle, &images, &markers);
  if (!summary.success) {
    *why = "the refinement failed: " + summary.message;
    return false;
  }
  *image = images[0];
  return true;
}

}  // namespace

bool WhiteReferencePoseOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(huber_px, 0.0);
  IBRDF_CHECK_OPTION_GT(corner_sigma_px, 0.0);
  IBRDF_CHECK_OPTION_GE(min_platform_markers, 1);
  IBRDF_CHECK_OPTION_GE(min_card_markers, 1);
  IBRDF_CHECK_OPTION_GT(max_rms_px, 0.0);
  IBRDF_CHECK_OPTION_GT(ambiguity_ratio, 0.0);
  return true;
}

std::string WhiteReferencePose::BriefReport() const {
  int used = 0, card_markers = 0;
  for (const WhiteReferencePhotoPose& photo : photos) {
    used += photo.used;
    if (photo.used) card_markers = std::max(card_markers, photo.card_markers);
  }
  char buffer[320];
  if (!posed) return "white reference: not posed";
  double intensity_sigma = 0.0;
  for (const auto& [light, sigma] : intensity_sigma_relative) intensity_sigma = std::max(intensity_sigma, sigma);
  std::snprintf(buffer, sizeof(buffer),
                "white reference: posed by its card's markers (up to %d) in %d of %zu photos, centre (%.4f, %.4f, "
                "%.4f) m, sigma %.3f mm, normal sigma %.3f deg (intensity sigma %.3f %%)",
                card_markers, used, photos.size(), center.x(), center.y(), center.z(),
                1e3 * std::sqrt(center_covariance.trace()), normal_sigma_deg, 100.0 * intensity_sigma);
  return buffer;
}

namespace {

// Poses white-reference photo `i` of `photos_session`: the camera against the platform's posed markers
// and the card against its own, each with its covariance; `pose->dropped_reason` says why a photo is
// not used.
void PosePhoto(const Session& photos_session, size_t i, const MarkerDictionary& dictionary,
               const std::map<int, BundleMarker>& platform, const std::map<int, BundleMarker>& card,
               const WhiteReferencePoseOptions& options, WhiteReferencePhotoPose* pose, Matrix6d* world_covariance,
               Matrix6d* card_covariance, Rigid3d* camera_from_card) {
  const Camera& camera = photos_session.camera;
  Image image = ReadImage(photos_session.PhotoPath(i));
  LinearizeImage(photos_session, i, &image);
  std::vector<MarkerDetection> detections = DetectMarkers(image, dictionary);
  RefineMarkerCorners(image, camera, &detections);
  std::map<int, int> seen;
  for (const MarkerDetection& d : detections) ++seen[d.id];
  detections.erase(
      std::remove_if(detections.begin(), detections.end(), [&](const MarkerDetection& d) { return seen[d.id] > 1; }),
      detections.end());
  BundleImage world_image = ImageOf(detections, platform, &pose->platform_markers);
  BundleImage card_image = ImageOf(detections, card, &pose->card_markers);
  char buffer[200];
  if (pose->platform_markers < options.min_platform_markers) {
    pose->dropped_reason = "only " + std::to_string(pose->platform_markers) + " posed platform markers seen (need " +
                          std::to_string(options.min_platform_markers) + ")";
    return;
  }
  if (pose->card_markers < options.min_card_markers) {
    pose->dropped_reason = "only " + std::to_string(pose->card_markers) + " of the card's markers seen (need " +
                          std::to_string(options.min_card_markers) + ")";
    return;
  }
  std::string failure;
  if (!PoseAgainst(camera, options, platform, &world_image, &failure)) {
    pose->dropped_reason = "no pose from the platform: " + failure;
    return;
  }
  if (!PoseAgainst(camera, options, card, &card_image, &failure)) {
    pose->dropped_reason = "no pose of the card: " + failure;
    return;
  }
  pose->platform_rms_px = world_image.rms_px;
  pose->card_rms_px = card_image.rms_px;
  if (std::max(pose->platform_rms_px, pose->card_rms_px) > options.max_rms_px) {
    std::snprintf(buffer, sizeof(buffer), "reprojection RMS %.3f px (platform) / %.3f px (card) above %.3f",
                  pose->platform_rms_px, pose->card_rms_px, options.max_rms_px);
    pose->dropped_reason = buffer;
    return;
  }
  Rigid3d alternative;
  pose->card_alternative_rms_px = AlternativePoseRms(camera, card_image, card, options.huber_px, &alternative);
  if (pose->card_alternative_rms_px >= 0.0 &&
      pose->card_alternative_rms_px < options.ambiguity_ratio * std::max(pose->card_rms_px, options.corner_sigma_px)) {
    std::snprintf(buffer, sizeof(buffer),
                  "ambiguous card pose: a second pose, %.1f deg away, explains its corners with RMS %.3f px (own "
                  "%.3f px); photograph the card less head-on or closer",
                  alternative.rotation.angularDistance(card_image.camera_from_world.rotation) * 180.0 / M_PI,
                  pose->card_alternative_rms_px, pose->card_rms_px);
    pose->dropped_reason = buffer;
    return;
  }
  pose->used = true;
  pose->camera_from_world = world_image.camera_from_world;
  *camera_from_card = card_image.camera_from_world;
  const Rigid3d world_from_card = world_image.camera_from_world.Inverse() * card_image.camera_from_world;
  pose->center = world_from_card.translation;
  pose->normal = world_from_card.rotation * Eigen::Vector3d::UnitZ();
  *world_covariance =
      PoseCovariance(camera, world_image, platform, std::max(options.corner_sigma_px, pose->platform_rms_px));
  *card_covariance = PoseCovariance(camera, card_image, card, std::max(options.corner_sigma_px, pose->card_rms_px));
}

// The relative sigma of each light's intensity that the pose's uncertainty implies: I ~ 1 / E(centre,
// normal) for a unit light, its gradient taken numerically.
void IntensitySensitivity(const Session& session, WhiteReferencePose* pose) {
  WhiteReferencePose& result = *pose;
  const WhiteReferenceSpec& white = *session.calibration->white_reference;
  for (size_t k = 0; k < session.lights.size(); ++k) {
    bool has_photos = false;
    for (const PhotoSpec& photo : white.photos) has_photos |= photo.light == k;
    if (!has_photos) continue;
    Light unit = session.lights[k];
    unit.intensity = Eigen::Vector3d::Ones();
    auto log_irradiance = [&](const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
      const Incidence incidence = IncidenceAt(unit, c, n.normalized());
      return incidence.lit ? std::log(incidence.irradiance[0]) : std::numeric_limits<double>::quiet_NaN();
    };
    Eigen::Vector3d center_gradient, normal_gradient;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d step = 1e-6 * Eigen::Vector3d::Unit(j);
      center_gradient[j] =
          (log_irradiance(result.center + step, result.normal) - log_irradiance(result.center - step, result.normal)) /
          2e-6;
      normal_gradient[j] =
          (log_irradiance(result.center, result.normal + step) - log_irradiance(result.center, result.normal - step)) /
          2e-6;
    }
    const double variance = center_gradient.dot(result.center_covariance * center_gradient) +
                            normal_gradient.dot(result.normal_covariance * normal_gradient);
    result.intensity_sigma_relative[k] = std::sqrt(std::max(0.0, variance));
  }
}

}  // namespace

WhiteReferencePose PoseWhiteReference(const Session& session, const std::map<int, BundleMarker>& world_markers,
                                      const MarkerDictionary& dictionary, const WhiteReferencePoseOptions& options) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("white reference pose options", why);
  IBRDF_CHECK(session.targets && session.targets->white_reference && session.calibration &&
              session.calibration->white_reference);
  const std::string where = session.manifest_path + ": /calibration/white_reference";
  const WhiteReferenceSpec& white = *session.calibration->white_reference;

  // The markers: the pose's posed ones (world frame) and the card's (card frame), all held fixed.
  std::map<int, BundleMarker> platform;
  for (const auto& [id, marker] : world_markers) {
    if (!marker.posed) continue;
    BundleMarker fixed = marker;
    fixed.fixed = true;
    platform[id] = fixed;
  }
  std::map<int, BundleMarker> card;
  for (const TargetSpec& target : session.targets->white_reference->markers) {
    if (target.id >= dictionary.size()) {
      ThrowError(session.manifest_path + ": /targets/white_reference",
                 "marker id " + std::to_string(target.id) + " is not in " + dictionary.name());
    }
    BundleMarker& marker = card[target.id];
    marker.id = target.id;
    marker.fixed = marker.posed = true;
    marker.corners = target.corners;
  }

  // The photos as the measurement photos are read: linearized by the session's chain.
  Session photos_session = session;
  photos_session.photos = white.photos;
  WhiteReferencePose result;
  result.photos.resize(white.photos.size());
  std::vector<Matrix6d> world_covariances(white.photos.size()), card_covariances(white.photos.size());
  std::vector<Rigid3d> camera_from_card(white.photos.size());
  for (size_t i = 0; i < white.photos.size(); ++i) {
    WhiteReferencePhotoPose& pose = result.photos[i];
    pose.photo = i;
    PosePhoto(photos_session, i, dictionary, platform, card, options, &pose, &world_covariances[i], &card_covariances[i],
              &camera_from_card[i]);
  }

  // The mean over the used photos and its covariance (independent photos: the sum over N^2).
  int used = 0;
  Eigen::Vector3d center_sum = Eigen::Vector3d::Zero(), normal_sum = Eigen::Vector3d::Zero();
  for (const WhiteReferencePhotoPose& pose : result.photos) {
    if (!pose.used) continue;
    ++used;
    center_sum += pose.center;
    normal_sum += pose.normal;
  }
  if (used == 0) {
    for (const WhiteReferencePhotoPose& pose : result.photos) {
      Log(1, "white-reference photo " + white.photos[pose.photo].file + ": " + pose.dropped_reason);
    }
    ThrowError(where,
               "the white reference cannot be posed from its card's markers: no white-reference photo sees enough of "
               "the platform's and the card's markers (reasons above)");
  }
  result.center = center_sum / used;
  result.normal = normal_sum.normalized();
  for (size_t i = 0; i < result.photos.size(); ++i) {
    const WhiteReferencePhotoPose& pose = result.photos[i];
    if (!pose.used) continue;
    result.spread_m = std::max(result.spread_m, (pose.center - result.center).norm());
    result.spread_deg =
        std::max(result.spread_deg, std::acos(std::clamp(pose.normal.dot(result.normal), -1.0, 1.0)) * 180.0 / M_PI);
    // The platform's error moves the whole card: camera_from_world x SmallMotion(d) puts world points
    // at SmallMotion(d)^-1 of theirs, so the centre moves by -t - w x c and the normal by -w x n.
    Eigen::Matrix<double, 3, 6> center_from_world, normal_from_world;
    center_from_world << -Eigen::Matrix3d::Identity(), Skew(pose.center);
    normal_from_world << Eigen::Matrix3d::Zero(), Skew(pose.normal);
    // The card's own error: world_from_card x SmallMotion(d) moves the centre by R t and the normal by
    // R (w x z).
    const Eigen::Matrix3d world_from_card_rotation =
        (pose.camera_from_world.Inverse() * camera_from_card[i]).rotation.toRotationMatrix();
    Eigen::Matrix<double, 3, 6> center_from_card, normal_from_card;
    center_from_card << world_from_card_rotation, Eigen::Matrix3d::Zero();
    normal_from_card << Eigen::Matrix3d::Zero(), -world_from_card_rotation * Skew(Eigen::Vector3d::UnitZ());
    result.center_covariance += center_from_world * world_covariances[i] * center_from_world.transpose() +
                                center_from_card * card_covariances[i] * center_from_card.transpose();
    result.normal_covariance += normal_from_world * world_covariances[i] * normal_from_world.transpose() +
                                normal_from_card * card_covariances[i] * normal_from_card.transpose();
  }
  result.center_covariance /= double(used) * used;
  result.normal_covariance /= double(used) * used;
  result.normal_sigma_deg =
      std::sqrt(std::max(
          0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(result.normal_covariance).eigenvalues().maxCoeff())) *
      180.0 / M_PI;

  IntensitySensitivity(session, &result);
  result.posed = true;
  result.total_s = timer.ElapsedSeconds();
  return result;
}

nlohmann::json ToJson(const WhiteReferencePose& pose) {
  nlohmann::json photos = nlohmann::json::array();
  for (const WhiteReferencePhotoPose& photo : pose.photos) {
    nlohmann::json entry = {{"photo", photo.photo},
                            {"used", photo.used},
                            {"platform_markers", photo.platform_markers},
                            {"card_markers", photo.card_markers}};
    if (photo.used) {
      entry["platform_rms_px"] = photo.platform_rms_px;
      entry["card_rms_px"] = photo.card_rms_px;
      entry["center"] = ToJson(photo.center);
      entry["normal"] = ToJson(photo.normal);
    } else {
      entry["dropped"] = photo.dropped_reason;
    }
    if (photo.card_alternative_rms_px >= 0.0) entry["card_alternative_pose_rms_px"] = photo.card_alternative_rms_px;
    photos.push_back(entry);
  }
  nlohmann::json json = {{"posed", pose.posed}, {"posed_by", "markers"}, {"photos", photos}};
  if (!pose.posed) return json;
  auto matrix = [](const Eigen::Matrix3d& m) {
    nlohmann::json rows = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) rows.push_back({m(i, 0), m(i, 1), m(i, 2)});
    return rows;
  };
  json["center"] = ToJson(pose.center);
  json["normal"] = ToJson(pose.normal);
  json["center_covariance_m2"] = matrix(pose.center_covariance);
  json["center_sigma_m"] = {std::sqrt(pose.center_covariance(0, 0)), std::sqrt(pose.center_covariance(1, 1)),
                            std::sqrt(pose.center_covariance(2, 2))};
  json["normal_covariance"] = matrix(pose.normal_covariance);
  json["normal_sigma_deg"] = pose.normal_sigma_deg;
  json["spread_m"] = pose.spread_m;
  json["spread_deg"] = pose.spread_deg;
  nlohmann::json sigma = nlohmann::json::object();
  for (const auto& [light, value] : pose.intensity_sigma_relative) sigma[std::to_string(light)] = value;
  json["intensity_sigma_relative"] = sigma;
  json["total_s"] = pose.total_s;
  return json;
}

}  // namespace ibrdf
