#include "calibrate/light_probe_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <Eigen/Geometry>

#include "calibrate/report_format.h"
#include "calibrate/sphere_silhouettes.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/light_json.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"
#include "radiometry/linear_image.h"

namespace ibrdf {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegreesPerRadian;
}

std::string LightName(const Light& light) { return light.id.empty() ? std::string("light") : light.id; }

// The nominal light's direction as seen from `center`.
Eigen::Vector3d NominalDirection(const Light& light, const Eigen::Vector3d& center) {
  return DirectionToLight(light, center);
}

nlohmann::json Vec2(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

// Median of a copy (the project's convention: rank n / 2).
double MedianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// One highlight's measurement, world frame.
struct Ray {
  Eigen::Vector3d origin;     // the highlight's surface point
  Eigen::Vector3d direction;  // towards the light
  Eigen::Matrix3d covariance;
  double sigma_rad = 0.0;
  double sigma_highlight_rad = 0.0;
  int placement = 0;
};

}  // namespace

bool LightProbeOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(kind == "directional" || kind == "point");
  IBRDF_CHECK_OPTION_GE(light_distance, 0.0);
  IBRDF_CHECK_OPTION_GT(warn_sigma_deg, 0.0);
  if (!silhouette.Check(why)) return false;
  return highlight.Check(why);
}

std::string LightProbeCalibration::BriefReport() const {
  if (!success) return "light probe: not calibrated";
  const char* kind = lights.empty() ? "directional" : LightKindName(lights[0].light.kind);
  return "light probe: " + std::to_string(lights.size()) + " " + kind + " lights from " +
         std::to_string(silhouettes.size()) + " placement" + (silhouettes.size() == 1 ? "" : "s") +
         FormatNumbers(", uncertainty median %.3f / max %.3f deg; from the nominal: median %.3f / max %.3f deg", median_sigma_deg,
             max_sigma_deg, median_angle_from_nominal_deg, max_angle_from_nominal_deg) +
         "; intensities " + intensity_reference;
}

nlohmann::json LightProbeCalibration::LightsJson() const {
  nlohmann::json out = nlohmann::json::array();
  for (const CalibratedLight& c : lights) {
    // Every calibrated light has an intensity: measured, or 1 where relative.
    Light light = c.light;
    light.has_intensity = true;
    nlohmann::json entry = LightJson(light);
    entry["id"] = light.id;
    out.push_back(entry);
  }
  return {{"lights", out}};
}

nlohmann::json LightProbeCalibration::ReportJson() const {
  nlohmann::json report;
  report["summary"] = BriefReport();
  report["intensity_reference"] = intensity_reference;
  nlohmann::json placements = nlohmann::json::array();
  for (size_t k = 0; k < silhouettes.size(); ++k) {
    const SphereSilhouette& s = silhouettes[k];
    placements.push_back({{"center", ToJson(centers[k])},
                          {"silhouette_center_px", Vec2(s.center_px)},
                          {"silhouette_radius_px", s.radius_px},
                          {"edge_points", s.points},
                          {"edge_points_dropped", s.rejected},
                          {"edge_rms_px", s.rms_px},
                          {"fitted", s.points > 0}});
  }
  report["placements"] = placements;
  nlohmann::json per_light = nlohmann::json::array();
  for (const CalibratedLight& c : lights) {
    nlohmann::json highlights = nlohmann::json::array();
    for (size_t k = 0; k < c.highlights.size(); ++k) {
      const Highlight& h = c.highlights[k];
      highlights.push_back({{"file", c.files[k]},
                            {"pixel", Vec2(h.pixel)},
                            {"core_pixel", Vec2(h.core)},
                            {"sigma_px", h.sigma_px},
                            {"blob_pixels", h.blob_pixels},
                            {"core_pixels", h.core_pixels},
                            {"second_spot_fraction", h.second_peak}});
    }
    nlohmann::json entry = {{"id", c.light.id},
                            {"sigma_deg", c.sigma_deg},
                            {"sigma_from_highlight_deg", c.sigma_from_highlight_deg},
                            {"angle_from_nominal_deg", c.angle_from_nominal_deg},
                            {"highlights", highlights}};
    switch (c.light.kind) {
      case Light::Kind::kPoint:
        entry["position_sigma_m"] = c.position_sigma_m;
        entry["position_from_nominal_m"] = c.position_from_nominal_m;
        break;
      case Light::Kind::kDirectional:
        break;
    }
    per_light.push_back(entry);
  }
  report["lights"] = per_light;
  report["median_sigma_deg"] = median_sigma_deg;
  report["max_sigma_deg"] = max_sigma_deg;
  report["median_angle_from_nominal_deg"] = median_angle_from_nominal_deg;
  report["max_angle_from_nominal_deg"] = max_angle_from_nominal_deg;
  report["total_s"] = total_s;
  return report;
}

namespace {

// The highlights of every light in every placement, by light id.
struct Observations {
  std::map<std::string, std::vector<Ray>> rays;
  std::map<std::string, std::vector<Highlight>> highlights;
  std::map<std::string, std::vector<std::string>> files;
};

// Placement `p`'s silhouettes (into `result`) and each of its photos' highlight, as a ray towards the
// photo's light (into `observations`).
void ObservePlacement(const Session& session, size_t p, const LightProbeOptions& options, LightProbeCalibration* result,
                      Observations* observations) {
  const std::string& manifest = session.manifest_path;
  if (session.sample.kind != SampleSpec::Kind::kSphere) {
    ThrowError(manifest + ": /sample/kind", "the light probe must be a sphere (a mirror ball), got " +
                                                std::string(SampleKindName(session.sample.kind)));
  }
  const double radius = session.sample.radius;
  SphereSilhouettes silhouettes(session, options.fit_silhouette, options.silhouette);
  bool any = false;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    if (photo.role != PhotoRole::kMeasurement) continue;
    const std::string photo_path = session.PhotoPath(i);
    if (!photo.camera_from_world) {
      ThrowError(photo_path, "the mirror-sphere photo has no camera_from_world pose (" + manifest + ")");
    }
    const Rigid3d& camera_from_world = *photo.camera_from_world;
    bool added = false;
    const SphereSilhouettes::Entry& entry = silhouettes.For(i, &added);
    const SphereSilhouette& silhouette = entry.silhouette;
    if (added) {
      const std::string mask_path = session.PhotoMaskPath(i);
      Log(1, silhouette.BriefReport() + (mask_path.empty() ? "" : " (" + mask_path + ")"));
      if (result->silhouettes.size() == p) {
        result->silhouettes.push_back(silhouette);
        result->centers.push_back(camera_from_world.Inverse() * silhouette.CenterInCamera(radius));
      }
    }
    const PixelMask* mask = entry.mask.width > 0 ? &entry.mask : nullptr;

    Image image = ReadImage(photo_path);
    LinearizeImage(session, i, &image);
    const Highlight highlight = LocateHighlight(image, silhouette, mask, options.highlight);
    const std::string id = LightName(session.PhotoLight(i));
    if (!highlight.found) ThrowError(photo_path, "no highlight of " + id + " on the mirror sphere: " + highlight.reason);
    const MirrorDirection direction = DirectionFromHighlight(session.camera, silhouette, radius, highlight);
    if (!direction.valid) ThrowError(photo_path, "the highlight of " + id + " gives no direction: " + direction.reason);
    const Eigen::Matrix3d world_from_camera = camera_from_world.rotation.inverse().toRotationMatrix();
    Ray ray;
    ray.origin = camera_from_world.Inverse() * direction.surface_point;
    ray.direction = world_from_camera * direction.direction;
    ray.covariance = world_from_camera * direction.covariance * world_from_camera.transpose();
    ray.sigma_rad = direction.sigma_deg / kDegreesPerRadian;
    ray.sigma_highlight_rad = direction.sigma_from_highlight_deg / kDegreesPerRadian;
    ray.placement = int(p);
    observations->rays[id].push_back(ray);
    observations->highlights[id].push_back(highlight);
    observations->files[id].push_back(photo_path);
    Log(2, id + ": " + highlight.BriefReport() + FormatNumbers(" -> +- %.3f deg", direction.sigma_deg));
    any = true;
  }
  if (!any) ThrowError(manifest, "no measurement photo of the mirror sphere");
}

// A point light's position from its rays: triangulated across placements, or at the given distance
// from the sphere's centre on the one placement's reflected ray.
void LocatePointLight(const std::string& manifest, const std::string& id, const std::vector<Ray>& list,
                      const std::vector<Eigen::Vector3d>& centers, const LightProbeOptions& options,
                      CalibratedLight* c) {
  std::vector<int> seen_placements;
  for (const Ray& ray : list) {
    if (std::find(seen_placements.begin(), seen_placements.end(), ray.placement) == seen_placements.end()) {
      seen_placements.push_back(ray.placement);
    }
  }
  if (seen_placements.size() >= 2) {
    std::vector<Eigen::Vector3d> origins, directions;
    std::vector<double> sigma;
    for (const Ray& ray : list) {
      origins.push_back(ray.origin);
      directions.push_back(ray.direction);
      sigma.push_back(ray.sigma_rad);
    }
    Eigen::Matrix3d covariance;
    if (!TriangulateRays(origins, directions, sigma, &c->light.position, &covariance)) {
      ThrowError(manifest, id + ": the reflected rays from the sphere's placements are (nearly) "
                                "parallel; move the sphere farther between the placements");
    }
    c->position_sigma_m = std::sqrt(std::max(0.0, covariance.trace()));
    return;
  }
  if (!(options.light_distance > 0)) {
    ThrowError(manifest, id + " was photographed at one sphere placement only: its position needs "
                              "a second placement or --light-distance-m");
  }
  // On the reflected ray, at the given distance from the sphere's centre.
  const Ray& ray = list[0];
  const Eigen::Vector3d oc = ray.origin - centers[ray.placement];
  const double b = oc.dot(ray.direction);
  const double t =
      -b + std::sqrt(std::max(0.0, b * b - oc.squaredNorm() + options.light_distance * options.light_distance));
  c->light.position = ray.origin + t * ray.direction;
  c->position_sigma_m = t * c->sigma_deg / kDegreesPerRadian;
}

// The calibrated light of `nominal` (a light of the first session) from its observations.
CalibratedLight CalibrateLight(const Session& first, const Light& nominal, const Observations& observations,
                               const std::vector<Eigen::Vector3d>& centers, const LightProbeOptions& options) {
  const bool point = options.kind == "point";
  const std::string id = LightName(nominal);
  const auto it = observations.rays.find(id);
  if (it == observations.rays.end()) ThrowError(first.manifest_path, id + " has no photo of the mirror sphere");
  const std::vector<Ray>& list = it->second;
  CalibratedLight c;
  c.nominal = nominal;
  c.light = nominal;
  c.light.id = nominal.id.empty() ? id : nominal.id;
  c.light.intensity = Eigen::Vector3d::Ones();
  c.photos = int(list.size());
  c.highlights = observations.highlights.at(id);
  c.files = observations.files.at(id);
  // The inverse-variance mean direction (several photos of one light, e.g. brackets or placements).
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weights = 0.0, weights_highlight = 0.0;
  for (const Ray& ray : list) {
    const double w = 1.0 / std::max(1e-18, ray.sigma_rad * ray.sigma_rad);
    sum += w * ray.direction;
    weights += w;
    weights_highlight += 1.0 / std::max(1e-18, ray.sigma_highlight_rad * ray.sigma_highlight_rad);
  }
  const Eigen::Vector3d direction = sum.normalized();
  c.sigma_deg = kDegreesPerRadian / std::sqrt(weights);
  c.sigma_from_highlight_deg = kDegreesPerRadian / std::sqrt(weights_highlight);
  const Eigen::Vector3d& center0 = centers[0];
  if (!point) {
    c.light.kind = Light::Kind::kDirectional;
    c.light.direction = direction;
  } else {
    c.light.kind = Light::Kind::kPoint;
    LocatePointLight(first.manifest_path, id, list, centers, options, &c);
    switch (nominal.kind) {
      case Light::Kind::kPoint:
        c.position_from_nominal_m = (nominal.position - c.light.position).norm();
        break;
      case Light::Kind::kDirectional:
        break;
    }
  }
  const Eigen::Vector3d calibrated_direction =
      point ? Eigen::Vector3d((c.light.position - center0).normalized()) : c.light.direction;
  c.angle_from_nominal_deg = AngleDeg(NominalDirection(nominal, center0), calibrated_direction);
  if (c.sigma_deg > options.warn_sigma_deg) {
    Log(1, "warning: " + id + FormatNumbers(" is uncertain: +- %.2f deg (over %.2f deg)", c.sigma_deg, options.warn_sigma_deg));
  }
  return c;
}

}  // namespace

LightProbeCalibration CalibrateLightProbe(const std::vector<Session>& placements, const LightProbeOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("light calibration options", why);
  if (placements.empty()) ThrowError("light calibration", "no mirror-sphere session given");
  const Timer timer;
  LightProbeCalibration result;
  if (options.kind == "point" && placements.size() < 2 && !(options.light_distance > 0)) {
    ThrowError(placements[0].manifest_path,
               "point lights need the mirror sphere at two places (two sessions) or the lights' distance from "
               "the sphere's centre (--light-distance-m)");
  }
  Observations observations;
  for (size_t p = 0; p < placements.size(); ++p) ObservePlacement(placements[p], p, options, &result, &observations);

  // Every light of the first session, in its order.
  const Session& first = placements[0];
  std::vector<double> sigmas, angles;
  for (const Light& nominal : first.lights) {
    result.lights.push_back(CalibrateLight(first, nominal, observations, result.centers, options));
    sigmas.push_back(result.lights.back().sigma_deg);
    angles.push_back(result.lights.back().angle_from_nominal_deg);
  }
  for (const auto& [id, list] : observations.rays) {
    bool listed = false;
    for (const Light& light : first.lights) listed = listed || LightName(light) == id;
    if (!listed)
      ThrowError(placements[list[0].placement].manifest_path,
                 "photos of light " + id + ", which the first session does not list");
  }
  result.median_sigma_deg = MedianOf(sigmas);
  result.max_sigma_deg = *std::max_element(sigmas.begin(), sigmas.end());
  result.median_angle_from_nominal_deg = MedianOf(angles);
  result.max_angle_from_nominal_deg = *std::max_element(angles.begin(), angles.end());
  result.total_s = timer.ElapsedSeconds();
  result.success = true;
  return result;
}

}  // namespace ibrdf
