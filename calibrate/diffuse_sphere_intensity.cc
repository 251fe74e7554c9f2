#include "calibrate/diffuse_sphere_intensity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "calibrate/lambertian.h"
#include "calibrate/report_format.h"
#include "calibrate/sphere_silhouettes.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "radiometry/linear_image.h"

namespace ibrdf {
namespace {

double MedianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// 1.4826 MAD / median.
double RelativeSpread(const std::vector<double>& values) {
  const double median = MedianOf(values);
  if (!(median > 0)) return 0.0;
  std::vector<double> deviations;
  deviations.reserve(values.size());
  for (double v : values) deviations.push_back(std::abs(v - median));
  return 1.4826 * MedianOf(deviations) / median;
}

std::string LightName(const Light& light) { return light.id.empty() ? std::string("light") : light.id; }

}  // namespace

bool DiffuseSphereOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(max_theta_i_deg, 1.0, 89.0);
  IBRDF_CHECK_OPTION_RANGE(max_theta_e_deg, 1.0, 89.0);
  IBRDF_CHECK_OPTION_GE(min_signal, 0.0);
  IBRDF_CHECK_OPTION_GE(rim_margin_px, 0.0);
  IBRDF_CHECK_OPTION_GT(min_pixels, 0);
  return silhouette.Check(why);
}

std::string DiffuseSphereIntensities::BriefReport() const {
  if (!success) return "diffuse sphere: not measured";
  int pixels = 0;
  for (const auto& l : lights) pixels += l.pixels;
  const double k = median_cosine_exponent;
  const std::string response = std::abs(k - 1.0) < 0.1       ? "consistent with a linear response"
                               : std::abs(k - 1 / 2.2) < 0.1 ? "looks gamma-encoded (sRGB-like)"
                                                             : "neither linear nor sRGB-like";
  return "diffuse sphere: " + std::to_string(lights.size()) + " lights, " +
         (absolute ? FormatNumbers("intensities from albedo (%.3f, %.3f, %.3f)", albedo.x(), albedo.y(), albedo.z())
                   : std::string("relative intensities (no albedo: mean 1)")) +
         ", " + std::to_string(pixels) + " pixels; cosine exponent " + FormatNumbers("%.3f", k) + " (" + response + ")" +
         FormatNumbers("; spread %.2f %% (calibrated directions) / %.2f %% (nominal)", 100 * median_spread,
             100 * median_nominal_spread);
}

nlohmann::json DiffuseSphereIntensities::ToJson() const {
  nlohmann::json per_light = nlohmann::json::array();
  for (const auto& l : lights) {
    per_light.push_back({{"id", l.id},
                         {"intensity", ibrdf::ToJson(l.intensity)},
                         {"spread", ibrdf::ToJson(l.spread)},
                         {"nominal_spread", ibrdf::ToJson(l.nominal_spread)},
                         {"cosine_exponent", l.cosine_exponent},
                         {"pixels", l.pixels},
                         {"saturated_pixels", l.saturated}});
  }
  return {{"summary", BriefReport()},
          {"absolute", absolute},
          {"albedo", absolute ? nlohmann::json(ibrdf::ToJson(albedo)) : nlohmann::json(nullptr)},
          {"center", ibrdf::ToJson(center)},
          {"silhouette_center_px", {silhouette.center_px.x(), silhouette.center_px.y()}},
          {"silhouette_radius_px", silhouette.radius_px},
          {"edge_rms_px", silhouette.rms_px},
          {"median_cosine_exponent", median_cosine_exponent},
          {"median_spread", median_spread},
          {"median_nominal_spread", median_nominal_spread},
          {"lights", per_light}};
}

namespace {

// The per-pixel estimates of one light's intensity over the diffuse sphere's photos.
struct Samples {
  std::vector<double> estimate[3], nominal[3];
  std::vector<double> log_cos, log_signal;
  int saturated = 0;
};

// Adds the usable pixels of photo `i` (under `light`, calibrated, and `nominal`, the session's) to
// `samples`: on the sphere inside `silhouette` less the rim margin and inside `mask`, lit and seen
// within the options' angles, not clipped, above the signal floor.
void SamplePhoto(const Session& diffuse, size_t i, const Light* light, const SphereSilhouette& silhouette,
                 const PixelMask& mask, const std::optional<Eigen::Vector3d>& albedo,
                 const DiffuseSphereOptions& options, Samples* out) {
  const PhotoSpec& photo = diffuse.photos[i];
  const std::string photo_path = diffuse.PhotoPath(i);
  const Light& nominal = diffuse.PhotoLight(i);
  const Rigid3d& camera_from_world = *photo.camera_from_world;
  const double radius = diffuse.sample.radius;
  const double cos_i_min = std::cos(options.max_theta_i_deg * kPi / 180.0);
  const double cos_e_min = std::cos(options.max_theta_e_deg * kPi / 180.0);
  const Eigen::Vector3d center_in_camera = silhouette.CenterInCamera(radius);
  const Eigen::Matrix3d world_from_camera = camera_from_world.rotation.inverse().toRotationMatrix();
  // The lights at unit intensity: their irradiance is the irradiance per unit of intensity.
  Light unit_light = *light, unit_nominal = nominal;
  unit_light.intensity = unit_nominal.intensity = Eigen::Vector3d::Ones();
  Samples& samples = *out;

  const Image raw = ReadImage(photo_path);
  Image radiance = raw;
  LinearizeImage(diffuse, i, &radiance, /*divide_by_exposure=*/true);
  const std::vector<uint8_t> saturated = SaturatedPixels(diffuse.radiometry, raw);
  const double to_signal = photo.exposure_s * photo.gain;
  const int channels = std::min(raw.channels, 3);
  for (int y = 0; y < raw.height; ++y) {
    for (int x = 0; x < raw.width; ++x) {
      const Eigen::Vector2d pixel(x + 0.5, y + 0.5);
      if ((pixel - silhouette.center_px).norm() > silhouette.radius_px - options.rim_margin_px) continue;
      if (mask.width > 0 && !mask.at(x, y)) continue;
      const Eigen::Vector2d xy = diffuse.camera.CamPlaneFromImage(pixel);
      const Eigen::Vector3d ray = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
      const double along = ray.dot(center_in_camera);
      const double off2 = (center_in_camera - along * ray).squaredNorm();
      if (off2 > radius * radius) continue;
      const Eigen::Vector3d p = (along - std::sqrt(radius * radius - off2)) * ray;
      const Eigen::Vector3d n_camera = (p - center_in_camera) / radius;
      if (-ray.dot(n_camera) < cos_e_min) continue;
      const Eigen::Vector3d p_world = camera_from_world.Inverse() * p;
      const Eigen::Vector3d n_world = world_from_camera * n_camera;
      const Incidence incidence = IncidenceAt(unit_light, p_world, n_world);
      const Incidence incidence_nominal = IncidenceAt(unit_nominal, p_world, n_world);
      const double cos_i = incidence.cos_theta, cos_nominal = incidence_nominal.cos_theta;
      if (cos_i < cos_i_min) continue;
      if (saturated[size_t(y) * raw.width + x]) {
        ++samples.saturated;
        continue;
      }
      double darkest = 1e300, mean = 0.0;
      for (int c = 0; c < channels; ++c) {
        darkest = std::min(darkest, radiance.at(x, y, c) * to_signal);
        mean += radiance.at(x, y, c) / channels;
      }
      if (!(darkest >= options.min_signal)) continue;
      for (int c = 0; c < 3; ++c) {
        const double value = radiance.at(x, y, std::min(c, channels - 1));
        const double rho = albedo ? (*albedo)[c] : 1.0;
        samples.estimate[c].push_back(LambertianIntensity(value, rho, incidence.irradiance[0]));
        if (cos_nominal > 0.05) {
          samples.nominal[c].push_back(LambertianIntensity(value, rho, incidence_nominal.irradiance[0]));
        }
      }
      samples.log_cos.push_back(std::log(cos_i));
      samples.log_signal.push_back(std::log(mean));
    }
  }
}

// One light's intensity from its samples: per channel the median and spread, and the cosine exponent.
DiffuseLightIntensity Summarize(const std::string& manifest, const std::string& id, const Samples& s,
                                const DiffuseSphereOptions& options) {
  DiffuseLightIntensity measured;
  measured.id = id;
  measured.pixels = int(s.estimate[0].size());
  measured.saturated = s.saturated;
  if (measured.pixels < options.min_pixels) {
    ThrowError(manifest, "light " + id + ": " + std::to_string(measured.pixels) +
                             " usable pixels on the diffuse "
                             "sphere, fewer than " +
                             std::to_string(options.min_pixels) + " (" + std::to_string(s.saturated) + " clipped)");
  }
  for (int c = 0; c < 3; ++c) {
    measured.intensity[c] = MedianOf(s.estimate[c]);
    measured.spread[c] = RelativeSpread(s.estimate[c]);
    measured.nominal_spread[c] = RelativeSpread(s.nominal[c]);
  }
  // Least-squares slope of log(signal) on log(cos(theta_i)).
  double mx = 0, my = 0;
  const size_t n = s.log_cos.size();
  for (size_t k = 0; k < n; ++k) {
    mx += s.log_cos[k] / n;
    my += s.log_signal[k] / n;
  }
  double sxy = 0, sxx = 0;
  for (size_t k = 0; k < n; ++k) {
    sxy += (s.log_cos[k] - mx) * (s.log_signal[k] - my);
    sxx += (s.log_cos[k] - mx) * (s.log_cos[k] - mx);
  }
  measured.cosine_exponent = sxx > 0 ? sxy / sxx : 0.0;
  return measured;
}

}  // namespace

DiffuseSphereIntensities MeasureDiffuseSphereIntensities(const Session& diffuse, std::vector<Light>* lights,
                                                         const std::optional<Eigen::Vector3d>& albedo,
                                                         const DiffuseSphereOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("diffuse sphere options", why);
  const std::string& manifest = diffuse.manifest_path;
  if (diffuse.sample.kind != SampleSpec::Kind::kSphere) {
    ThrowError(manifest + ": /sample/kind",
               "the diffuse reference must be a sphere, got " + std::string(SampleKindName(diffuse.sample.kind)));
  }
  if (albedo && !((albedo->array() > 0).all() && (albedo->array() <= 1).all())) {
    ThrowError("--albedo", "each channel must be in (0, 1]");
  }
  DiffuseSphereIntensities result;
  result.absolute = albedo.has_value();
  if (albedo) result.albedo = *albedo;
  const double radius = diffuse.sample.radius;

  std::map<std::string, Samples> by_light;
  SphereSilhouettes silhouettes(diffuse, options.fit_silhouette, options.silhouette);
  bool first = true;
  for (size_t i = 0; i < diffuse.photos.size(); ++i) {
    const PhotoSpec& photo = diffuse.photos[i];
    if (photo.role != PhotoRole::kMeasurement) continue;
    const std::string photo_path = diffuse.PhotoPath(i);
    const std::string id = LightName(diffuse.PhotoLight(i));
    const Light* light = nullptr;
    for (const Light& l : *lights) light = (LightName(l) == id) ? &l : light;
    if (!light) ThrowError(photo_path, "photo of light " + id + ", which the calibration does not have");
    if (!photo.camera_from_world) ThrowError(photo_path, "the photo has no camera_from_world pose (" + manifest + ")");
    bool added = false;
    const SphereSilhouettes::Entry& entry = silhouettes.For(i, &added);
    if (added && first) {
      result.silhouette = entry.silhouette;
      result.center = photo.camera_from_world->Inverse() * entry.silhouette.CenterInCamera(radius);
      Log(1, "diffuse sphere " + entry.silhouette.BriefReport());
      first = false;
    }
    SamplePhoto(diffuse, i, light, entry.silhouette, entry.mask, albedo, options, &by_light[id]);
  }

  std::vector<double> exponents, spreads, nominal_spreads;
  for (Light& light : *lights) {
    const std::string id = LightName(light);
    const auto it = by_light.find(id);
    if (it == by_light.end()) ThrowError(manifest, "light " + id + " has no photo of the diffuse sphere");
    const DiffuseLightIntensity measured = Summarize(manifest, id, it->second, options);
    exponents.push_back(measured.cosine_exponent);
    spreads.push_back(measured.spread.mean());
    nominal_spreads.push_back(measured.nominal_spread.mean());
    result.lights.push_back(measured);
  }
  if (!albedo) {
    // Relative: the mean over lights and channels is 1.
    double mean = 0.0;
    for (const auto& l : result.lights) mean += l.intensity.mean() / result.lights.size();
    for (auto& l : result.lights) l.intensity /= mean;
  }
  for (size_t k = 0; k < lights->size(); ++k) {
    (*lights)[k].intensity = result.lights[k].intensity;
    (*lights)[k].has_intensity = true;
  }
  result.median_cosine_exponent = MedianOf(exponents);
  result.median_spread = MedianOf(spreads);
  result.median_nominal_spread = MedianOf(nominal_spreads);
  result.success = true;
  return result;
}

}  // namespace ibrdf
