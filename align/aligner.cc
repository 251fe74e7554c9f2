#include "align/aligner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "align/bundle_adjustment.h"
#include "align/cylinder_fit.h"
#include "align/light_fit.h"
#include "align/markers.h"
#include "align/sphere_fit.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/logging.h"
#include "radiometry/linear_image.h"

namespace ibrdf {
namespace {

// The markers of the pose, by id: known layout (fixed), unknown layout (free; the origin marker fixed),
// and the sample's (free; their layout in the sample frame serves the cylinder fit only).
struct PoseMarkers {
  std::map<int, BundleMarker> markers;
  std::map<int, std::string> kinds;  // "reference", "unknown" or "sample"
  std::set<int> light_ids;           // markers on the light (not markers of the pose)
};

// The session's markers, their ids checked against the dictionary. Throws Error naming the block.
PoseMarkers CollectMarkers(const Session& session, const MarkerDictionary& dictionary) {
  const TargetsSpec& targets = *session.targets;
  auto check_id = [&](int id, const std::string& block) {
    if (id >= dictionary.size()) {
      ThrowError(session.manifest_path + ": /targets/" + block,
                 "marker id " + std::to_string(id) + " is not in " + dictionary.name());
    }
  };
  PoseMarkers pose;
  for (const TargetSpec& target : targets.reference) {
    check_id(target.id, "reference");
    BundleMarker& marker = pose.markers[target.id];
    marker.id = target.id;
    marker.fixed = marker.posed = true;
    marker.corners = target.corners;
    pose.kinds[target.id] = "reference";
  }
  if (targets.unknown_layout) {
    const UnknownLayoutSpec& layout = *targets.unknown_layout;
    for (const int id : layout.ids) {
      check_id(id, "unknown_layout");
      BundleMarker& marker = pose.markers[id];
      marker.id = id;
      marker.size = layout.size;
      pose.kinds[id] = "unknown";
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
      BundleMarker& marker = pose.markers[target.id];
      marker.id = target.id;
      marker.size = (target.corners[1] - target.corners[0]).norm();
      pose.kinds[target.id] = "sample";
    }
  }
  if (targets.light) {
    if (session.lights.at(targets.light->light).kind != Light::Kind::kPoint) {
      ThrowError(session.manifest_path + ": /targets/light", "markers on the light need a point light");
    }
    for (const LightMarkerSpec& marker : targets.light->markers) {
      check_id(marker.id, "light");
      pose.light_ids.insert(marker.id);
    }
  }
  return pose;
}

// Detected light markers of one photo: id -> corners.
using LightDetections = std::map<int, std::array<Eigen::Vector2d, 4>>;

// Reads, linearizes and detects markers in every photo: the corners of the pose's markers go to
// `bundle_images`, the light's to `light_detections`; the linear images stay in `images`.
void DetectMarkersInPhotos(const Session& session, const MarkerDictionary& dictionary, const PoseMarkers& pose,
                           AlignResult* result, std::vector<BundleImage>* bundle_images,
                           std::vector<LightDetections>* light_detections, std::vector<Image>* images) {
  ProgressBar progress("detect", session.photos.size());
  tbb::parallel_for(size_t(0), session.photos.size(), [&](size_t i) {
    ImageAlignment& alignment = result->images[i];
    alignment.photo = i;
    // Linearized in place, so detection sees the same contrast whatever the file's response; the
    // sphere fit reads the same linear image later.
    (*images)[i] = ReadImage(session.PhotoPath(i));
    Image& linear = (*images)[i];
    LinearizeImage(session, i, &linear);
    std::map<int, int> seen;
    std::vector<MarkerDetection> detections = DetectMarkers(linear, dictionary);
    RefineMarkerCorners(linear, session.camera, &detections);
    for (const MarkerDetection& d : detections) ++seen[d.id];
    for (const MarkerDetection& d : detections) {
      if (pose.light_ids.count(d.id) && seen[d.id] == 1) {
        ++alignment.light_markers;
        (*light_detections)[i][d.id] = d.corners;
        continue;
      }
      if (!pose.markers.count(d.id) || seen[d.id] > 1) {
        ++alignment.ignored_markers;
        continue;
      }
      for (int k = 0; k < 4; ++k) (*bundle_images)[i].corners.push_back({d.id, k, d.corners[k], true});
    }
    progress.Add(1);
  });
  progress.Finish();
}

// Fills `alignment` from a photo's bundle-adjusted pose and returns why it must be dropped (empty: kept).
std::string CheckPose(const Camera& camera, const AlignOptions& options, const BundleImage& image,
                      const std::map<int, BundleMarker>& markers, ImageAlignment* alignment) {
  std::set<int> seen;
  for (const CornerObservation& o : image.corners) {
    if (markers.at(o.marker_id).posed) seen.insert(o.marker_id);
  }
  alignment->markers = static_cast<int>(seen.size());
  alignment->outlier_corners = image.outliers;
  alignment->rms_px = image.rms_px;
  alignment->camera_from_world = image.camera_from_world;
  const PoseUncertainty uncertainty =
      EstimatePoseUncertainty(camera, image, markers, std::max(options.corner_sigma_px, image.rms_px));
  alignment->position_sigma_m = uncertainty.position_sigma_m;
  alignment->rotation_sigma_deg = uncertainty.rotation_sigma_deg;
  Rigid3d alternative;
  alignment->alternative_rms_px = AlternativePoseRms(camera, image, markers, options.huber_px, &alternative);
  char buffer[200];
  if (alignment->markers < options.min_markers_per_image) {
    return "only " + std::to_string(alignment->markers) + " posed markers seen (need " +
           std::to_string(options.min_markers_per_image) + ")";
  }
  if (image.rms_px > options.max_image_rms_px) {
    std::snprintf(buffer, sizeof(buffer), "reprojection RMS %.3f px above %.3f", image.rms_px,
                  options.max_image_rms_px);
    return buffer;
  }
  if (!(uncertainty.position_sigma_m <= options.max_position_sigma_m) ||
      !(uncertainty.rotation_sigma_deg <= options.max_rotation_sigma_deg)) {
    std::snprintf(buffer, sizeof(buffer),
                  "pose poorly determined by its corners (nearly collinear or too few, small or distant markers): "
                  "position sigma %.3f mm (limit %.3f), rotation sigma %.4f deg (limit %.4f)",
                  1e3 * uncertainty.position_sigma_m, 1e3 * options.max_position_sigma_m,
                  uncertainty.rotation_sigma_deg, options.max_rotation_sigma_deg);
    return buffer;
  }
  if (alignment->alternative_rms_px >= 0.0 &&
      alignment->alternative_rms_px < options.ambiguity_ratio * std::max(image.rms_px, options.corner_sigma_px)) {
    std::snprintf(buffer, sizeof(buffer),
                  "ambiguous pose: a second pose, %.1f deg away, explains the coplanar corners with RMS %.3f px "
                  "(own %.3f px)",
                  alternative.rotation.angularDistance(image.camera_from_world.rotation) * 180.0 / M_PI,
                  alignment->alternative_rms_px, image.rms_px);
    return buffer;
  }
  return "";
}

// Poses: chained start, then the bundle adjustment; photos that fail a check are dropped and the
// adjustment repeated without them. Fills result->images and result->bundle.
void PosePhotos(const Session& session, const AlignOptions& options, std::vector<BundleImage>* bundle_images,
                std::map<int, BundleMarker>* markers, AlignResult* result) {
  const Camera& camera = session.camera;
  InitializeByChaining(camera, options.huber_px, bundle_images, markers);
  BundleAdjustmentOptions bundle_options = options.bundle;
  bundle_options.huber_px = options.huber_px;
  for (int round = 0; round < 4; ++round) {
    if (std::none_of(bundle_images->begin(), bundle_images->end(), [](const BundleImage& b) { return b.posed; })) break;
    result->bundle = BundleAdjust(camera, bundle_options, bundle_images, markers);
    if (!result->bundle.success && round == 0) {
      ThrowError(session.manifest_path + ": /targets", "the bundle adjustment failed: " + result->bundle.message);
    }
    if (!result->bundle.success) {
      // Dropping photos cut the rest off from the fixed markers: they cannot be posed either.
      for (size_t i = 0; i < session.photos.size(); ++i) {
        if (!(*bundle_images)[i].posed) continue;
        (*bundle_images)[i].posed = false;
        result->images[i].dropped_reason =
            "no pose once the photos linking it to the fixed markers were dropped (" + result->bundle.message + ")";
      }
      break;
    }
    bool dropped = false;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      BundleImage& image = (*bundle_images)[i];
      if (!image.posed) continue;
      result->images[i].dropped_reason = CheckPose(camera, options, image, *markers, &result->images[i]);
      if (!result->images[i].dropped_reason.empty()) {
        image.posed = false;
        dropped = true;
      }
    }
    if (!dropped) break;
  }
  for (size_t i = 0; i < session.photos.size(); ++i) {
    ImageAlignment& alignment = result->images[i];
    alignment.used = (*bundle_images)[i].posed;
    if (alignment.used || !alignment.dropped_reason.empty()) continue;
    std::set<int> detected;
    for (const CornerObservation& o : (*bundle_images)[i].corners) detected.insert(o.marker_id);
    alignment.markers = static_cast<int>(detected.size());
    alignment.dropped_reason = detected.empty() ? "no marker of the pose seen"
                                                : "no pose: none of its " + std::to_string(detected.size()) +
                                                      " markers could be posed from the others";
  }
  // Markers no used photo sees have no estimate.
  for (auto& [id, marker] : *markers) {
    if (!marker.fixed && marker.images == 0) marker.posed = false;
  }
}

// The corner RMS over the used photos and each posed marker's residual.
void SummarizeResiduals(const std::vector<BundleImage>& bundle_images, const PoseMarkers& pose, AlignResult* result) {
  double all_squared = 0.0;
  size_t all_count = 0;
  for (size_t i = 0; i < bundle_images.size(); ++i) {
    if (!result->images[i].used) continue;
    all_squared += bundle_images[i].rms_px * bundle_images[i].rms_px * bundle_images[i].inliers;
    all_count += bundle_images[i].inliers;
  }
  for (const auto& [id, marker] : pose.markers) {
    if (!marker.posed) continue;
    MarkerResidual residual;
    residual.id = id;
    residual.kind = pose.kinds.at(id);
    residual.observations = marker.images;
    residual.rms_px = marker.rms_px;
    residual.corners = marker.corners;
    result->markers.push_back(residual);
  }
  result->rms_px = all_count ? std::sqrt(all_squared / all_count) : 0.0;
}

// The light fit's view of the used photos: their poses, light markers and layout corners.
std::vector<LightFitPhoto> LightFitPhotos(const std::vector<BundleImage>& bundle_images,
                                          const std::vector<LightDetections>& light_detections,
                                          const std::map<int, BundleMarker>& markers, const AlignResult& result) {
  std::vector<LightFitPhoto> photos;
  for (size_t i = 0; i < bundle_images.size(); ++i) {
    if (!result.images[i].used) continue;
    LightFitPhoto photo;
    photo.photo = i;
    photo.camera_from_world = result.images[i].camera_from_world;
    photo.light_markers = light_detections[i];
    for (const CornerObservation& o : bundle_images[i].corners) {
      const BundleMarker& marker = markers.at(o.marker_id);
      if (o.inlier && marker.posed) photo.layout_corners.push_back({o.pixel, marker.corners[o.corner]});
    }
    photos.push_back(std::move(photo));
  }
  return photos;
}

// The aligned session: used photos with their poses, the fitted light; markers of unknown layout that
// were posed join the reference layout, the others stay unknown.
Session AlignedSession(const Session& session, const AlignResult& result, const std::map<int, BundleMarker>& markers) {
  Session aligned = session;
  aligned.photos.clear();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (!result.images[i].used) continue;
    PhotoSpec photo = session.photos[i];
    photo.camera_from_world = result.images[i].camera_from_world;
    aligned.photos.push_back(photo);
  }
  if (result.light.fitted) {
    Light& light = aligned.lights.at(session.targets->light->light);
    light.position = result.light.position;
    light.placement_known = true;
  }
  const TargetsSpec& targets = *session.targets;
  if (targets.unknown_layout) {
    TargetsSpec& aligned_targets = *aligned.targets;
    std::vector<int> unposed;
    for (const int id : targets.unknown_layout->ids) {
      const BundleMarker& marker = markers.at(id);
      if (marker.posed) {
        TargetSpec target;
        target.id = id;
        target.corners = marker.corners;
        aligned_targets.reference.push_back(target);
      } else {
        unposed.push_back(id);
      }
    }
    aligned_targets.unknown_layout.reset();
    if (!unposed.empty()) {
      UnknownLayoutSpec rest;
      rest.size = targets.unknown_layout->size;
      rest.ids = unposed;
      aligned_targets.unknown_layout = rest;
    }
  }
  return aligned;
}

}  // namespace

bool AlignOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(min_markers_per_image, 1);
  IBRDF_CHECK_OPTION_GT(max_image_rms_px, 0.0);
  IBRDF_CHECK_OPTION_GT(huber_px, 0.0);
  IBRDF_CHECK_OPTION_GT(corner_sigma_px, 0.0);
  IBRDF_CHECK_OPTION_GT(max_position_sigma_m, 0.0);
  IBRDF_CHECK_OPTION_GT(max_rotation_sigma_deg, 0.0);
  IBRDF_CHECK_OPTION_GT(ambiguity_ratio, 0.0);
  return bundle.Check(why) && cylinder.Check(why) && sphere.Check(why) && light.Check(why);
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
  PoseMarkers pose = CollectMarkers(session, dictionary);
  session.CheckPhotos();

  AlignResult result;
  result.images.resize(session.photos.size());
  std::vector<BundleImage> bundle_images(session.photos.size());
  std::vector<LightDetections> light_detections(session.photos.size());
  std::vector<Image> images(session.photos.size());
  DetectMarkersInPhotos(session, dictionary, pose, &result, &bundle_images, &light_detections, &images);
  PosePhotos(session, options, &bundle_images, &pose.markers, &result);
  SummarizeResiduals(bundle_images, pose, &result);

  // The light from its markers; the photos that see them take the poses of that joint refinement.
  if (options.fit_light && targets.light) {
    LightFitOptions light_options = options.light;
    light_options.huber_px = options.huber_px;
    result.light =
        FitLightToMarkers(session.camera, *targets.light,
                          LightFitPhotos(bundle_images, light_detections, pose.markers, result), light_options);
    for (const auto& [i, camera_from_world] : result.light.refined_camera_from_world) {
      result.images[i].camera_from_world = camera_from_world;
    }
  }
  result.session = AlignedSession(session, result, pose.markers);
  if (result.session.photos.empty()) {
    for (const ImageAlignment& image : result.images) {
      Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
    }
    ThrowError(session.manifest_path, "no photo could be aligned (see the reasons above)");
  }
  // A light the session could not place must come from its markers: no stage may use its placeholder.
  for (const Light& light : result.session.lights) {
    if (light.placement_known) continue;
    int light_photos = 0, posed = 0;
    for (const ImageAlignment& image : result.images) {
      if (session.photos[image.photo].role != PhotoRole::kTargets) continue;
      ++light_photos;
      posed += image.used;
      if (!image.used) Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
    }
    std::string cause = result.light.reason.empty() ? "its markers gave no position" : result.light.reason;
    if (!options.fit_light) cause = "the light fit is switched off";
    ThrowError(session.manifest_path,
               "light fit failed: " + LightLabel(light) + "'s position is unknown and " + cause + " (" +
                   std::to_string(posed) + " of " + std::to_string(light_photos) +
                   " light photos posed; at least one must see the light's markers): photograph the light's "
                   "card closer or at a higher resolution, or state the position (session init "
                   "--light-position-m)");
  }

  // The white reference from its card's markers: its photos' poses, its centre and normal.
  if (options.pose_white_reference && targets.white_reference && session.calibration &&
      session.calibration->white_reference) {
    WhiteReferencePoseOptions white_options = options.white_reference;
    white_options.huber_px = options.huber_px;
    white_options.corner_sigma_px = options.corner_sigma_px;
    result.white_reference = PoseWhiteReference(session, pose.markers, dictionary, white_options);
    WhiteReferenceSpec& white = *result.session.calibration->white_reference;
    white.center = result.white_reference.center;
    white.normal = result.white_reference.normal;
    white.posed = true;
    std::vector<PhotoSpec> posed;
    for (const WhiteReferencePhotoPose& photo : result.white_reference.photos) {
      if (!photo.used) {
        Log(1, "white-reference photo " + white.photos[photo.photo].file + " left out: " + photo.dropped_reason);
        continue;
      }
      posed.push_back(white.photos[photo.photo]);
      posed.back().camera_from_world = photo.camera_from_world;
    }
    // A light that only the left-out photos measured would lose its intensity: refuse, with the reason.
    for (const WhiteReferencePhotoPose& photo : result.white_reference.photos) {
      const size_t light = white.photos[photo.photo].light;
      const bool measured =
          std::any_of(posed.begin(), posed.end(), [&](const PhotoSpec& p) { return p.light == light; });
      if (!photo.used && !measured && !session.lights[light].has_intensity) {
        ThrowError(session.manifest_path + ": /calibration/white_reference/photos/" + std::to_string(photo.photo),
                   white.photos[photo.photo].file + " cannot be posed (" + photo.dropped_reason + ") and no other " +
                       "white-reference photo measures " + LightLabel(session.lights[light]) + "'s intensity");
      }
    }
    white.photos = posed;
    Log(1, result.white_reference.BriefReport());
  }

  // The sphere from its silhouettes in the used measurement photos (target photos show no sample).
  if (options.fit_sphere && session.sample.kind == SampleSpec::Kind::kSphere) {
    std::vector<SilhouettePhoto> photos;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      if (!result.images[i].used || session.photos[i].role == PhotoRole::kTargets) continue;
      photos.push_back({&images[i], result.images[i].camera_from_world});
    }
    SphereFitOptions sphere_options = options.sphere;
    sphere_options.fix_radius = sphere_options.fix_radius || session.sample.radius_known;
    result.sphere =
        FitSphereToSilhouettes(session.camera, photos, session.sample.center, session.sample.radius, sphere_options);
    if (!result.sphere.warning.empty()) Log(1, "warning: sphere fit: " + result.sphere.warning);
    if (result.sphere.fitted) {
      result.session.sample.center = result.sphere.center;
      result.session.sample.radius = result.sphere.radius;
    }
  }
  // The cylinder from the markers fixed to it.
  if (options.fit_cylinder && session.sample.kind == SampleSpec::Kind::kCylinder && targets.sample) {
    result.cylinder = FitCylinderToMarkers(*targets.sample, pose.markers, session.sample, options.cylinder);
    if (result.cylinder.fitted) {
      result.session.sample.center = result.cylinder.center;
      result.session.sample.axis = result.cylinder.axis;
    }
  }
  result.total_s = timer.ElapsedSeconds();
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
    report += sphere.BriefReport();
  } else if (mesh_registered) {
    report += "mesh registered to the markers (a new world_from_mesh)";
  } else {
    report += "sample pose as given";
  }
  if (light.fitted || !light.reason.empty()) report += "; " + light.BriefReport();
  if (white_reference.posed) report += "; " + white_reference.BriefReport();
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
                      {"rms_m", result.sphere.rms_m},
                      {"radius_known", result.sphere.radius_fixed},
                      {"limb_balance", result.sphere.limb_balance},
                      {"radius_amplification", result.sphere.radius_amplification},
                      {"one_sided", result.sphere.one_sided}};
    nlohmann::json covariance = nlohmann::json::array();
    for (int i = 0; i < 4; ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (int j = 0; j < 4; ++j) row.push_back(result.sphere.covariance(i, j));
      covariance.push_back(row);
    }
    json["sphere"]["covariance_m2"] = covariance;
    json["sphere"]["center_sigma_m"] = {std::sqrt(result.sphere.covariance(0, 0)),
                                        std::sqrt(result.sphere.covariance(1, 1)),
                                        std::sqrt(result.sphere.covariance(2, 2))};
    json["sphere"]["radius_sigma_m"] = std::sqrt(result.sphere.covariance(3, 3));
    if (!result.sphere.warning.empty()) {
      json["sphere"]["warning"] = result.sphere.warning;
      json["warnings"].push_back("sphere fit: " + result.sphere.warning);
    }
  }
  if (result.white_reference.posed) json["white_reference"] = ToJson(result.white_reference);
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
