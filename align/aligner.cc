#include "align/aligner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "align/bundle_adjustment.h"
#include "align/cost_functions/marker_corner_error.h"
#include "align/cost_functions/reprojection_error.h"
#include "align/cost_functions/sphere_tangent_error.h"
#include "align/cylinder_fit.h"
#include "align/markers.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/linear_image.h"
#include "core/json_reader.h"
#include "core/logging.h"

namespace ibrdf {
namespace {

// Silhouette edge points of a sphere in one photo: along radial lines from the sphere's projected
// centre, the sharpest drop from a lit limb to the dark background, located at sub-pixel precision
// where the profile crosses the mid level. Edges against anything bright (the platform) or on the
// unlit side (no contrast) are skipped.
std::vector<Eigen::Vector2d> SilhouettePoints(const Image& image, const Camera& camera,
                                              const Rigid3d& camera_from_world, const Eigen::Vector3d& center,
                                              double radius, int lines, double band_px) {
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector3d c = camera_from_world * center;
  if (!(c.z() > radius)) return points;
  const Eigen::Vector2d center_px = camera.ImageFromCamera(c);
  const double radius_px = camera.FocalX() * radius / std::sqrt(c.squaredNorm() - radius * radius);
  const double step = 0.25;
  for (int k = 0; k < lines; ++k) {
    const double angle = 2.0 * M_PI * k / lines;
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    // Search the band around the predicted silhouette, with room for the inside and outside levels.
    const double s0 = radius_px - band_px - 3.0, s1 = radius_px + band_px + 3.0;
    std::vector<double> profile;
    for (double s = s0; s <= s1; s += step)
      profile.push_back(BilinearLuminance(image, center_px.x() + s * direction.x(), center_px.y() + s * direction.y()));
    if (std::any_of(profile.begin(), profile.end(), [](double v) { return !std::isfinite(v); })) continue;
    // The sharpest drop over one pixel.
    const int span = static_cast<int>(1.0 / step);
    int best = -1;
    double best_drop = 0.0;
    for (size_t i = 0; i + span < profile.size(); ++i) {
      const double drop = profile[i] - profile[i + span];
      if (drop > best_drop) {
        best_drop = drop;
        best = static_cast<int>(i);
      }
    }
    const int guard = static_cast<int>(2.0 / step);
    if (best < guard || best + span + guard >= static_cast<int>(profile.size())) continue;
    const double inside = profile[best - guard + span / 2];
    const double outside = profile[best + span + guard];
    if (!(inside > 0.03) || !(outside < 0.1 * inside)) continue;
    // A rise before the edge means something brighter than the limb lies just beyond it (a white card
    // behind the sphere): the drop found is that thing's edge, not the limb. Skip the line.
    bool rises = false;
    for (int i = 0; i + span <= best && !rises; ++i) rises = profile[i + span] - profile[i] > 0.25 * inside;
    if (rises) continue;
    // Sub-pixel: the crossing of the mid level between the two ends of the steepest drop (the limb
    // pixel and the first background pixel); the level further inside may differ from the limb's.
    const double mid = 0.5 * (profile[best] + profile[best + span]);
    double edge = -1.0;
    for (int i = best - guard; i < best + span + guard; ++i) {
      if (profile[i] >= mid && profile[i + 1] < mid) {
        edge = s0 + step * (i + (profile[i] - mid) / (profile[i] - profile[i + 1]));
        break;
      }
    }
    if (edge < 0.0) continue;
    points.push_back(center_px + edge * direction);
  }
  return points;
}

// Options for the stage's small problems (a pose, a few marker poses, a sphere): dense QR, tight
// tolerances so sub-millimetre answers converge fully.
ceres::Solver::Options SmallProblemOptions(double tolerance) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 100;
  options.function_tolerance = tolerance;
  options.parameter_tolerance = tolerance;
  return options;
}

// A light marker seen in one posed photo.
struct LightSighting {
  size_t photo;
  std::array<Eigen::Vector2d, 4> corners;
};

}  // namespace

bool AlignOptions::Check(std::string* why) const {
  if (min_markers_per_image < 1 || !(max_image_rms_px > 0.0) || !(huber_px > 0.0) || silhouette_lines < 8 ||
      !(corner_sigma_px > 0.0) || !(max_position_sigma_m > 0.0) || !(max_rotation_sigma_deg > 0.0) ||
      !(ambiguity_ratio > 0.0)) {
    *why =
        "min_markers_per_image >= 1, max_image_rms_px > 0, huber_px > 0, silhouette_lines >= 8, corner_sigma_px > 0, "
        "max_position_sigma_m > 0, max_rotation_sigma_deg > 0, ambiguity_ratio > 0";
    return false;
  }
  return bundle.Check(why) && cylinder.Check(why);
}

AlignResult AlignSession(const Session& session, const AlignOptions& options) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("align options", why);
  if (!session.targets || (session.targets->reference.empty() && !session.targets->unknown_layout)) {
    ThrowError(session.manifest_path + ": /targets",
               "align needs markers of known layout (reference) or of unknown layout (unknown_layout)");
  }
  const TargetsSpec& targets = *session.targets;
  const MarkerDictionary dictionary(targets.dictionary, session.manifest_path + ": /targets/dictionary");
  auto check_id = [&](int id, const std::string& block) {
    if (id >= dictionary.size()) {
      ThrowError(session.manifest_path + ": /targets/" + block,
                 "marker id " + std::to_string(id) + " is not in " + dictionary.name());
    }
  };
  // The markers of the pose: known layout (fixed), unknown layout (free; the origin marker fixed), and
  // the sample's (free; their layout in the sample frame serves the cylinder fit only).
  std::map<int, BundleMarker> markers;
  std::map<int, std::string> kinds;
  for (const TargetSpec& target : targets.reference) {
    check_id(target.id, "reference");
    BundleMarker& marker = markers[target.id];
    marker.id = target.id;
    marker.fixed = marker.posed = true;
    marker.corners = target.corners;
    kinds[target.id] = "reference";
  }
  if (targets.unknown_layout) {
    const UnknownLayoutSpec& layout = *targets.unknown_layout;
    for (const int id : layout.ids) {
      check_id(id, "unknown_layout");
      BundleMarker& marker = markers[id];
      marker.id = id;
      marker.size = layout.size;
      kinds[id] = "unknown";
      if (layout.origin_id && *layout.origin_id == id) {
        // The world frame: origin at the marker's centre, x to the right, y up the print, z out of it.
        const double h = 0.5 * layout.size;
        marker.fixed = marker.posed = true;
        marker.corners = {Eigen::Vector3d(-h, h, 0.0), Eigen::Vector3d(h, h, 0.0), Eigen::Vector3d(h, -h, 0.0),
                          Eigen::Vector3d(-h, -h, 0.0)};
        marker.world_from_marker =
            Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())), Eigen::Vector3d::Zero());
      }
    }
  }
  if (targets.sample) {
    for (const TargetSpec& target : targets.sample->markers) {
      check_id(target.id, "sample");
      BundleMarker& marker = markers[target.id];
      marker.id = target.id;
      marker.size = (target.corners[1] - target.corners[0]).norm();
      kinds[target.id] = "sample";
    }
  }
  std::map<int, const LightMarkerSpec*> light_markers;
  if (targets.light) {
    if (session.light.kind != Light::Kind::kPoint) {
      ThrowError(session.manifest_path + ": /targets/light", "markers on the light need a point light");
    }
    for (const LightMarkerSpec& marker : targets.light->markers) {
      check_id(marker.id, "light");
      light_markers[marker.id] = &marker;
    }
  }
  session.CheckPhotos();
  const Camera& camera = session.camera;
  const std::array<double, 8> intrinsics = ProjectionIntrinsics(camera);
  const cv::Mat camera_matrix =
      (cv::Mat_<double>(3, 3) << intrinsics[0], 0, intrinsics[2] - 0.5, 0, intrinsics[1], intrinsics[3] - 0.5, 0, 0, 1);
  const cv::Mat distortion = (cv::Mat_<double>(1, 4) << intrinsics[4], intrinsics[5], intrinsics[6], intrinsics[7]);

  AlignResult result;
  result.images.resize(session.photos.size());
  std::vector<BundleImage> bundle_images(session.photos.size());
  std::vector<std::map<int, std::array<Eigen::Vector2d, 4>>> light_detections(session.photos.size());
  std::vector<Image> images(session.photos.size());
  ProgressBar progress("detect", session.photos.size());
  tbb::parallel_for(size_t(0), session.photos.size(), [&](size_t i) {
    ImageAlignment& alignment = result.images[i];
    alignment.photo = i;
    // Linearized in place, so detection sees the same contrast whatever the file's response; the
    // sphere fit reads the same linear image later.
    images[i] = ReadImage(session.PhotoPath(i));
    Image& linear = images[i];
    LinearizeImage(session, i, &linear);
    std::map<int, int> seen;
    std::vector<MarkerDetection> detections = DetectMarkers(linear, dictionary);
    RefineMarkerCorners(linear, camera, &detections);
    for (const MarkerDetection& d : detections) ++seen[d.id];
    for (const MarkerDetection& d : detections) {
      if (light_markers.count(d.id) && seen[d.id] == 1) {
        ++alignment.light_markers;
        light_detections[i][d.id] = d.corners;
        continue;
      }
      if (!markers.count(d.id) || seen[d.id] > 1) {
        ++alignment.ignored_markers;
        continue;
      }
      for (int k = 0; k < 4; ++k) bundle_images[i].corners.push_back({d.id, k, d.corners[k], true});
    }
    progress.Add(1);
  });
  progress.Finish();

  // Poses: chained start, then the bundle adjustment; photos that fail a check are dropped and the
  // adjustment repeated without them.
  InitializeByChaining(camera, options.huber_px, &bundle_images, &markers);
  BundleAdjustmentOptions bundle_options = options.bundle;
  bundle_options.huber_px = options.huber_px;
  for (int round = 0; round < 4; ++round) {
    if (std::none_of(bundle_images.begin(), bundle_images.end(), [](const BundleImage& b) { return b.posed; })) break;
    result.bundle = BundleAdjust(camera, bundle_options, &bundle_images, &markers);
    if (!result.bundle.success && round == 0) {
      ThrowError(session.manifest_path + ": /targets", "the bundle adjustment failed: " + result.bundle.message);
    }
    if (!result.bundle.success) {
      // Dropping photos cut the rest off from the fixed markers: they cannot be posed either.
      for (size_t i = 0; i < session.photos.size(); ++i) {
        if (!bundle_images[i].posed) continue;
        bundle_images[i].posed = false;
        result.images[i].dropped_reason =
            "no pose once the photos linking it to the fixed markers were dropped (" + result.bundle.message + ")";
      }
      break;
    }
    bool dropped = false;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      BundleImage& image = bundle_images[i];
      ImageAlignment& alignment = result.images[i];
      if (!image.posed) continue;
      std::set<int> seen;
      for (const CornerObservation& o : image.corners) {
        if (markers.at(o.marker_id).posed) seen.insert(o.marker_id);
      }
      alignment.markers = static_cast<int>(seen.size());
      alignment.outlier_corners = image.outliers;
      alignment.rms_px = image.rms_px;
      alignment.camera_from_world = image.camera_from_world;
      const PoseUncertainty uncertainty =
          EstimatePoseUncertainty(camera, image, markers, std::max(options.corner_sigma_px, image.rms_px));
      alignment.position_sigma_m = uncertainty.position_sigma_m;
      alignment.rotation_sigma_deg = uncertainty.rotation_sigma_deg;
      Rigid3d alternative;
      alignment.alternative_rms_px = AlternativePoseRms(camera, image, markers, options.huber_px, &alternative);
      char buffer[200];
      if (alignment.markers < options.min_markers_per_image) {
        alignment.dropped_reason = "only " + std::to_string(alignment.markers) + " posed markers seen (need " +
                                   std::to_string(options.min_markers_per_image) + ")";
      } else if (image.rms_px > options.max_image_rms_px) {
        std::snprintf(buffer, sizeof(buffer), "reprojection RMS %.3f px above %.3f", image.rms_px,
                      options.max_image_rms_px);
        alignment.dropped_reason = buffer;
      } else if (!(uncertainty.position_sigma_m <= options.max_position_sigma_m) ||
                 !(uncertainty.rotation_sigma_deg <= options.max_rotation_sigma_deg)) {
        std::snprintf(buffer, sizeof(buffer),
                      "pose poorly determined by its corners (nearly collinear or too few, small or distant markers): "
                      "position sigma %.3f mm (limit %.3f), rotation sigma %.4f deg (limit %.4f)",
                      1e3 * uncertainty.position_sigma_m, 1e3 * options.max_position_sigma_m,
                      uncertainty.rotation_sigma_deg, options.max_rotation_sigma_deg);
        alignment.dropped_reason = buffer;
      } else if (alignment.alternative_rms_px >= 0.0 &&
                 alignment.alternative_rms_px <
                     options.ambiguity_ratio * std::max(image.rms_px, options.corner_sigma_px)) {
        std::snprintf(buffer, sizeof(buffer),
                      "ambiguous pose: a second pose, %.1f deg away, explains the coplanar corners with RMS %.3f px "
                      "(own %.3f px)",
                      alternative.rotation.angularDistance(image.camera_from_world.rotation) * 180.0 / M_PI,
                      alignment.alternative_rms_px, image.rms_px);
        alignment.dropped_reason = buffer;
      }
      if (!alignment.dropped_reason.empty()) {
        image.posed = false;
        dropped = true;
      }
    }
    if (!dropped) break;
  }
  for (size_t i = 0; i < session.photos.size(); ++i) {
    ImageAlignment& alignment = result.images[i];
    alignment.used = bundle_images[i].posed;
    if (alignment.used || !alignment.dropped_reason.empty()) continue;
    std::set<int> detected;
    for (const CornerObservation& o : bundle_images[i].corners) detected.insert(o.marker_id);
    alignment.markers = static_cast<int>(detected.size());
    alignment.dropped_reason = detected.empty() ? "no marker of the pose seen"
                                                : "no pose: none of its " + std::to_string(detected.size()) +
                                                      " markers could be posed from the others";
  }
  // Markers no used photo sees have no estimate.
  for (auto& [id, marker] : markers) {
    if (!marker.fixed && marker.images == 0) marker.posed = false;
  }
  double all_squared = 0.0;
  size_t all_count = 0;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (!result.images[i].used) continue;
    all_squared += bundle_images[i].rms_px * bundle_images[i].rms_px * bundle_images[i].inliers;
    all_count += bundle_images[i].inliers;
  }
  for (const auto& [id, marker] : markers) {
    if (!marker.posed) continue;
    MarkerResidual residual;
    residual.id = id;
    residual.kind = kinds.at(id);
    residual.observations = marker.images;
    residual.rms_px = marker.rms_px;
    residual.corners = marker.corners;
    result.markers.push_back(residual);
  }
  result.rms_px = all_count ? std::sqrt(all_squared / all_count) : 0.0;

  // The light from its markers. Each marker's pose starts from a square PnP in one photo (the
  // candidate that best explains all photos seeing it); then one Ceres problem refines the light
  // markers' poses together with the poses of the photos that see them, whose reference corners stay
  // in the problem (the known layout keeps gauge and scale): the light markers, large and seen
  // square-on, tie those photos' poses to each other. The light is where the markers say, averaged.
  if (options.fit_light && session.targets->light) {
    LightFit& fit = result.light;
    const double half = 0.5 * session.targets->light->size;
    const std::array<Eigen::Vector3d, 4> corners_in_marker = {
        Eigen::Vector3d(-half, -half, 0.0), Eigen::Vector3d(half, -half, 0.0), Eigen::Vector3d(half, half, 0.0),
        Eigen::Vector3d(-half, half, 0.0)};
    std::vector<cv::Point3d> object;
    for (const Eigen::Vector3d& c : corners_in_marker) object.emplace_back(c.x(), c.y(), c.z());
    std::map<size_t, std::array<double, 6>> cameras;  // photo -> camera_from_world (angle-axis, translation)
    std::vector<std::vector<LightSighting>> sightings(session.targets->light->markers.size());
    std::vector<std::array<double, 6>> marker_poses(sightings.size());  // world_from_marker
    for (size_t m = 0; m < sightings.size(); ++m) {
      const int id = session.targets->light->markers[m].id;
      for (size_t i = 0; i < session.photos.size(); ++i) {
        const auto it = light_detections[i].find(id);
        if (!result.images[i].used || it == light_detections[i].end()) continue;
        sightings[m].push_back({i, it->second});
        if (!cameras.count(i))
          AngleAxisFromPose(result.images[i].camera_from_world, cameras[i].data(), cameras[i].data() + 3);
      }
    }
    auto sighting_cost = [&](const LightSighting& sighting, const double* marker_pose, double* squared) {
      const double* pose = cameras.at(sighting.photo).data();
      for (int c = 0; c < 4; ++c) {
        double residual[2];
        MarkerCornerError(intrinsics, corners_in_marker[c], sighting.corners[c].x(), sighting.corners[c].y())(
            pose, pose + 3, marker_pose, marker_pose + 3, residual);
        *squared += residual[0] * residual[0] + residual[1] * residual[1];
      }
    };
    ceres::Problem problem;
    for (size_t m = 0; m < sightings.size(); ++m) {
      // The start: both of IPPE's solutions in every photo, the one that best explains all photos.
      double best_cost = std::numeric_limits<double>::infinity();
      for (const LightSighting& sighting : sightings[m]) {
        std::vector<cv::Point2d> pixels;
        for (const Eigen::Vector2d& p : sighting.corners) pixels.emplace_back(p.x() - 0.5, p.y() - 0.5);
        std::vector<cv::Mat> rvecs, tvecs;
        cv::solvePnPGeneric(object, pixels, camera_matrix, distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE);
        for (size_t k = 0; k < rvecs.size(); ++k) {
          const double r[3] = {rvecs[k].at<double>(0), rvecs[k].at<double>(1), rvecs[k].at<double>(2)};
          const double t[3] = {tvecs[k].at<double>(0), tvecs[k].at<double>(1), tvecs[k].at<double>(2)};
          std::array<double, 6> candidate;
          AngleAxisFromPose(result.images[sighting.photo].camera_from_world.Inverse() * PoseFromAngleAxis(r, t),
                            candidate.data(), candidate.data() + 3);
          double cost = 0.0;
          for (const LightSighting& other : sightings[m]) sighting_cost(other, candidate.data(), &cost);
          if (cost < best_cost) {
            best_cost = cost;
            marker_poses[m] = candidate;
          }
        }
      }
      for (const LightSighting& sighting : sightings[m]) {
        double* pose = cameras.at(sighting.photo).data();
        for (int c = 0; c < 4; ++c) {
          problem.AddResidualBlock(MarkerCornerError::Create(intrinsics, corners_in_marker[c], sighting.corners[c].x(),
                                                             sighting.corners[c].y()),
                                   new ceres::HuberLoss(options.huber_px), pose, pose + 3, marker_poses[m].data(),
                                   marker_poses[m].data() + 3);
        }
      }
    }
    // The layout's corners (known, or as the bundle adjustment estimated them) stay constant here.
    auto usable = [&](const CornerObservation& o) { return o.inlier && markers.at(o.marker_id).posed; };
    std::vector<std::array<double, 3>> layout_points;
    for (const auto& [i, pose] : cameras) {
      for (const CornerObservation& o : bundle_images[i].corners) {
        if (usable(o)) layout_points.push_back({});
      }
    }
    size_t next_point = 0;
    for (auto& [i, pose] : cameras) {
      for (const CornerObservation& o : bundle_images[i].corners) {
        if (!usable(o)) continue;
        const Eigen::Vector3d& p = markers.at(o.marker_id).corners[o.corner];
        std::array<double, 3>& point = layout_points[next_point++];
        point = {p.x(), p.y(), p.z()};
        problem.AddResidualBlock(ReprojectionError::Create(intrinsics, o.pixel.x(), o.pixel.y()),
                                 new ceres::HuberLoss(options.huber_px), pose.data(), pose.data() + 3, point.data());
        problem.SetParameterBlockConstant(point.data());
      }
    }
    bool solved = true;
    if (problem.NumResidualBlocks() > 0) {
      const ceres::Solver::Options solver_options = SmallProblemOptions(1e-14);
      ceres::Solver::Summary summary;
      ceres::Solve(solver_options, &problem, &summary);
      solved = summary.IsSolutionUsable();
      if (!solved)
        fit.reason = "the light markers' refinement failed (" + summary.message + "); the light stays as given";
    }
    if (solved) {
      for (const auto& [i, pose] : cameras)
        result.images[i].camera_from_world = PoseFromAngleAxis(pose.data(), pose.data() + 3);
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int estimated = 0;
    for (size_t m = 0; m < sightings.size(); ++m) {
      const LightMarkerSpec& spec = session.targets->light->markers[m];
      LightMarkerFit marker;
      marker.id = spec.id;
      marker.photos = solved ? static_cast<int>(sightings[m].size()) : 0;
      if (marker.photos > 0) {
        double squared = 0.0;
        for (const LightSighting& sighting : sightings[m]) sighting_cost(sighting, marker_poses[m].data(), &squared);
        marker.rms_px = std::sqrt(squared / (4.0 * sightings[m].size()));
        marker.world_from_marker = PoseFromAngleAxis(marker_poses[m].data(), marker_poses[m].data() + 3);
        marker.light_in_world = marker.world_from_marker * spec.light_in_marker;
        sum += marker.light_in_world;
        ++estimated;
      }
      fit.markers.push_back(marker);
    }
    if (estimated == 0) {
      if (fit.reason.empty()) fit.reason = "no marker of the light was seen in a posed photo; the light stays as given";
    } else {
      fit.fitted = true;
      fit.position = sum / estimated;
      for (const LightMarkerFit& marker : fit.markers) {
        if (marker.photos > 0) fit.spread_m = std::max(fit.spread_m, (marker.light_in_world - fit.position).norm());
      }
    }
  }

  // The aligned session: used photos with their poses.
  result.session = session;
  result.session.photos.clear();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (!result.images[i].used) continue;
    PhotoSpec photo = session.photos[i];
    photo.camera_from_world = result.images[i].camera_from_world;
    result.session.photos.push_back(photo);
  }
  if (result.light.fitted) result.session.light.position = result.light.position;
  // Markers of unknown layout that were posed join the reference layout; the others stay unknown.
  if (targets.unknown_layout) {
    TargetsSpec& aligned = *result.session.targets;
    std::vector<int> unposed;
    for (const int id : targets.unknown_layout->ids) {
      const BundleMarker& marker = markers.at(id);
      if (marker.posed) {
        TargetSpec target;
        target.id = id;
        target.corners = marker.corners;
        aligned.reference.push_back(target);
      } else {
        unposed.push_back(id);
      }
    }
    aligned.unknown_layout.reset();
    if (!unposed.empty()) {
      UnknownLayoutSpec rest;
      rest.size = targets.unknown_layout->size;
      rest.ids = unposed;
      aligned.unknown_layout = rest;
    }
  }
  if (result.session.photos.empty()) {
    for (const ImageAlignment& image : result.images)
      Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
  }
  if (result.session.photos.empty())
    ThrowError(session.manifest_path, "no photo could be aligned (see the reasons above)");

  // The sphere from its silhouettes: rays through sub-pixel limb points are tangent to it. Three
  // rounds, each extracting limb points in a band around the current estimate's silhouette (wide, then
  // narrow) and fitting with a Cauchy loss, so edges of other things (a card behind the limb) do not
  // pull the fit; the last round drops points beyond 3 RMS and refits.
  if (options.fit_sphere && session.sample.kind == SampleSpec::Kind::kSphere) {
    double center[3] = {session.sample.center.x(), session.sample.center.y(), session.sample.center.z()};
    double radius = session.sample.radius;
    SphereFit& fit = result.sphere;
    const double bands_px[] = {0.15, 3.0, 1.5};  // the first as a fraction of the radius
    for (int round = 0; round < 3; ++round) {
      std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rays;  // origin, direction
      const Eigen::Vector3d current(center[0], center[1], center[2]);
      for (size_t i = 0; i < session.photos.size(); ++i) {
        if (!result.images[i].used || session.photos[i].role == PhotoRole::kTargets) continue;
        const Rigid3d& pose = result.images[i].camera_from_world;
        const Rigid3d world_from_camera = pose.Inverse();
        const Eigen::Vector3d c = pose * current;
        const double radius_px =
            camera.FocalX() * radius / std::sqrt(std::max(c.squaredNorm() - radius * radius, 1e-12));
        const double band = round == 0 ? bands_px[0] * radius_px : bands_px[round];
        for (const Eigen::Vector2d& p :
             SilhouettePoints(images[i], camera, pose, current, radius, options.silhouette_lines, band)) {
          const Eigen::Vector2d xy = camera.CamPlaneFromImage(p);
          rays.emplace_back(world_from_camera.translation,
                            world_from_camera.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized());
        }
      }
      if (rays.size() < 8) break;
      std::vector<bool> keep(rays.size(), true);
      for (int pass = 0; pass < (round == 2 ? 2 : 1); ++pass) {
        ceres::Problem problem;
        for (size_t k = 0; k < rays.size(); ++k) {
          if (!keep[k]) continue;
          problem.AddResidualBlock(SphereTangentError::Create(rays[k].first, rays[k].second),
                                   new ceres::CauchyLoss(2e-4), center, &radius);
        }
        problem.SetParameterLowerBound(&radius, 0, 1e-6);
        const ceres::Solver::Options solver_options = SmallProblemOptions(1e-15);
        ceres::Solver::Summary summary;
        ceres::Solve(solver_options, &problem, &summary);
        std::vector<double> residuals(rays.size());
        double squared = 0.0;
        int count = 0;
        for (size_t k = 0; k < rays.size(); ++k) {
          SphereTangentError(rays[k].first, rays[k].second)(center, &radius, &residuals[k]);
          if (keep[k]) {
            squared += residuals[k] * residuals[k];
            ++count;
          }
        }
        fit.rms_m = std::sqrt(squared / std::max(count, 1));
        fit.silhouette_points = count;
        fit.rejected_points = static_cast<int>(rays.size()) - count;
        if (pass == 0 && round == 2) {
          for (size_t k = 0; k < rays.size(); ++k) keep[k] = std::abs(residuals[k]) <= 3.0 * fit.rms_m;
        }
      }
    }
    if (fit.silhouette_points >= 8) {
      fit.fitted = true;
      fit.center = Eigen::Vector3d(center[0], center[1], center[2]);
      fit.radius = radius;
      result.session.sample.center = fit.center;
      result.session.sample.radius = fit.radius;
    }
  }
  // The cylinder from the markers fixed to it.
  if (options.fit_cylinder && session.sample.kind == SampleSpec::Kind::kCylinder && targets.sample) {
    result.cylinder = FitCylinderToMarkers(*targets.sample, markers, session.sample, options.cylinder);
    if (result.cylinder.fitted) {
      result.session.sample.center = result.cylinder.center;
      result.session.sample.axis = result.cylinder.axis;
    }
  }
  result.total_s = timer.ElapsedSeconds();
  result.success = true;
  return result;
}

std::string AlignResult::BriefReport() const {
  int used = 0;
  for (const ImageAlignment& image : images) used += image.used;
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer), "align: %d of %zu photos posed, corner RMS %.3f px, %zu markers; ", used,
                images.size(), rms_px, markers.size());
  std::string report = buffer;
  if (cylinder.fitted || !cylinder.reason.empty()) {
    report += cylinder.BriefReport();
  } else if (sphere.fitted) {
    std::snprintf(
        buffer, sizeof(buffer),
        "sphere centre (%.5f, %.5f, %.5f) m, radius %.5f m from %d silhouette points (RMS %.3f mm, %d rejected)",
        sphere.center.x(), sphere.center.y(), sphere.center.z(), sphere.radius, sphere.silhouette_points,
        1e3 * sphere.rms_m, sphere.rejected_points);
    report += buffer;
  } else {
    report += "sample pose as given";
  }
  if (light.fitted) {
    std::snprintf(buffer, sizeof(buffer), "; light at (%.5f, %.5f, %.5f) m from %zu markers (spread %.3f mm)",
                  light.position.x(), light.position.y(), light.position.z(), light.markers.size(),
                  1e3 * light.spread_m);
    report += buffer;
  } else if (!light.reason.empty()) {
    report += "; " + light.reason;
  }
  return report;
}

nlohmann::json ToJson(const AlignResult& result) {
  nlohmann::json images = nlohmann::json::array();
  for (const ImageAlignment& image : result.images) {
    nlohmann::json entry = {{"photo", image.photo},
                            {"used", image.used},
                            {"markers", image.markers},
                            {"light_markers", image.light_markers},
                            {"ignored_markers", image.ignored_markers},
                            {"outlier_corners", image.outlier_corners},
                            {"rms_px", image.rms_px}};
    if (image.used || image.position_sigma_m > 0.0) {
      entry["position_sigma_m"] =
          std::isfinite(image.position_sigma_m) ? nlohmann::json(image.position_sigma_m) : nlohmann::json(nullptr);
      entry["rotation_sigma_deg"] =
          std::isfinite(image.rotation_sigma_deg) ? nlohmann::json(image.rotation_sigma_deg) : nlohmann::json(nullptr);
    }
    if (image.alternative_rms_px >= 0.0) entry["alternative_pose_rms_px"] = image.alternative_rms_px;
    if (!image.used) entry["dropped"] = image.dropped_reason;
    images.push_back(entry);
  }
  nlohmann::json markers = nlohmann::json::array();
  for (const MarkerResidual& marker : result.markers) {
    nlohmann::json entry = {
        {"id", marker.id}, {"kind", marker.kind}, {"observations", marker.observations}, {"rms_px", marker.rms_px}};
    if (marker.kind != "reference") {
      nlohmann::json corners = nlohmann::json::array();
      for (const Eigen::Vector3d& c : marker.corners) corners.push_back(ToJson(c));
      entry["corners"] = corners;
    }
    markers.push_back(entry);
  }
  nlohmann::json json = {{"format", "ibrdf-alignment"}, {"version", 1},
                         {"rms_px", result.rms_px},     {"images", images},
                         {"markers", markers},          {"total_s", result.total_s}};
  json["bundle_adjustment"] = {{"images", result.bundle.images},
                               {"free_markers", result.bundle.free_markers},
                               {"fixed_markers", result.bundle.fixed_markers},
                               {"corners", result.bundle.corners},
                               {"outlier_corners", result.bundle.outliers},
                               {"initial_rms_px", result.bundle.initial_rms_px},
                               {"final_rms_px", result.bundle.final_rms_px},
                               {"iterations", result.bundle.iterations}};
  if (result.cylinder.fitted) {
    json["cylinder"] = {{"center", ToJson(result.cylinder.center)},
                        {"axis", ToJson(result.cylinder.axis)},
                        {"markers", result.cylinder.markers},
                        {"rejected_markers", result.cylinder.rejected_markers},
                        {"rms_m", result.cylinder.rms_m}};
  } else if (!result.cylinder.reason.empty()) {
    json["cylinder"] = {{"fitted", false}, {"reason", result.cylinder.reason}};
  }
  if (result.sphere.fitted) {
    json["sphere"] = {{"center", ToJson(result.sphere.center)},
                      {"radius", result.sphere.radius},
                      {"silhouette_points", result.sphere.silhouette_points},
                      {"rejected_points", result.sphere.rejected_points},
                      {"rms_m", result.sphere.rms_m}};
  }
  if (result.light.fitted || !result.light.reason.empty()) {
    nlohmann::json light_markers = nlohmann::json::array();
    for (const LightMarkerFit& marker : result.light.markers) {
      nlohmann::json entry = {{"id", marker.id}, {"photos", marker.photos}};
      if (marker.photos > 0) {
        entry["rms_px"] = marker.rms_px;
        entry["light_in_world"] = ToJson(marker.light_in_world);
      }
      light_markers.push_back(entry);
    }
    json["light"] = {{"fitted", result.light.fitted}, {"markers", light_markers}};
    if (result.light.fitted) {
      json["light"]["position"] = ToJson(result.light.position);
      json["light"]["spread_m"] = result.light.spread_m;
    } else {
      json["light"]["reason"] = result.light.reason;
    }
  }
  return json;
}

}  // namespace ibrdf
