#include "calibrate/white_reference_intensity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "calibrate/lambertian.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/math.h"
#include "core/statistics.h"
#include "radiometry/radiance_image.h"

namespace ibrdf {
namespace {

// The pixel box holding the image of a disc (centre, normal, radius), with a 2-pixel margin; the
// whole image where part of the disc is behind the camera.
void DiscBox(const Camera& camera, const Rigid3d& camera_from_world, const Eigen::Vector3d& center,
             const Eigen::Vector3d& normal, double radius, int box[4]) {
  box[0] = 0, box[1] = 0, box[2] = camera.width, box[3] = camera.height;
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  constexpr int kPoints = 64;
  for (int k = 0; k < kPoints; ++k) {
    const double angle = 2.0 * M_PI * k / kPoints;
    // The 64-gon's vertices on a circle 1 % wider contain the disc.
    const Eigen::Vector3d p =
        camera_from_world * (center + 1.01 * radius * (std::cos(angle) * u + std::sin(angle) * v));
    if (!(p.z() > 1e-6)) return;
    const Eigen::Vector2d pixel = camera.ImageFromCamera(p);
    if (!pixel.allFinite()) return;
    x0 = std::min(x0, pixel.x()), x1 = std::max(x1, pixel.x());
    y0 = std::min(y0, pixel.y()), y1 = std::max(y1, pixel.y());
  }
  box[0] = std::clamp(static_cast<int>(std::floor(x0)) - 2, 0, camera.width);
  box[1] = std::clamp(static_cast<int>(std::floor(y0)) - 2, 0, camera.height);
  box[2] = std::clamp(static_cast<int>(std::ceil(x1)) + 2, 0, camera.width);
  box[3] = std::clamp(static_cast<int>(std::ceil(y1)) + 2, 0, camera.height);
}

}  // namespace

bool LightCalibrationOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(interior_fraction, 0.0);
  IBRDF_CHECK_OPTION_LE(interior_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(min_signal, 0.0);
  IBRDF_CHECK_OPTION_GE(max_saturated_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(max_saturated_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(min_pixels, 1);
  IBRDF_CHECK_OPTION_GT(max_theta_deg, 0.0);
  IBRDF_CHECK_OPTION_LT(max_theta_deg, 90.0);
  return true;
}

std::string LightCalibrationReport::BriefReport() const {
  if (!calibrated)
    return "light calibration: none (the session has no white reference; its light intensities are used as stated)";
  std::string text = "light calibration: white reference, " + std::to_string(photos) + " photos";
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), " in %.2f s", total_s);
  text += buffer;
  for (const LightIntensityReport& light : lights) {
    char stated[128] = "not stated";
    if (light.stated) {
      std::snprintf(stated, sizeof(stated), "(%.6g, %.6g, %.6g)", light.stated_intensity[0], light.stated_intensity[1],
                    light.stated_intensity[2]);
    }
    std::snprintf(buffer, sizeof(buffer),
                  "; %s%s%d photos, %llu of %llu interior pixels: intensity %s -> (%.6g, %.6g, %.6g), spread %.2f %%, "
                  "%.2f %%, %.2f %%; rejected: ",
                  light.light.empty() ? "" : "light ", light.light.empty() ? "" : (light.light + ": ").c_str(),
                  light.photos, static_cast<unsigned long long>(light.pixels_used),
                  static_cast<unsigned long long>(light.interior_pixels), stated, light.calibrated_intensity[0],
                  light.calibrated_intensity[1], light.calibrated_intensity[2], 100.0 * light.spread[0],
                  100.0 * light.spread[1], 100.0 * light.spread[2]);
    text += buffer + FormatCounts(light.rejected);
  }
  return text;
}

nlohmann::json LightCalibrationReport::ToJson() const {
  nlohmann::json per_light = nlohmann::json::array();
  for (const LightIntensityReport& light : lights) {
    nlohmann::json entry = {{"light", light.light},
                            {"photos", light.photos},
                            {"calibrated_intensity", ibrdf::ToJson(light.calibrated_intensity)},
                            {"interior_pixels", light.interior_pixels},
                            {"pixels_used", light.pixels_used},
                            {"rejected", light.rejected},
                            {"spread", ibrdf::ToJson(light.spread)}};
    entry["stated_intensity"] = light.stated ? ibrdf::ToJson(light.stated_intensity) : nlohmann::json(nullptr);
    per_light.push_back(entry);
  }
  return {{"summary", BriefReport()},
          {"photos", photos},
          {"lights", per_light},
          {"verdicts", VerdictsToJson(verdicts)},
          {"total_s", total_s}};
}

namespace {

// The white reference's measurement of light `light_index` from the white-reference photos `photos`
// (indices into white.photos) taken under it.
void CalibrateLight(const Session& session, size_t light_index, const std::vector<size_t>& photos,
                    const LightCalibrationOptions& options, LightIntensityReport* report) {
  const WhiteReferenceSpec& white = *session.calibration->white_reference;
  const Light& light = session.lights[light_index];
  const std::string where = session.manifest_path + ": /calibration/white_reference";
  const std::string label = session.lights.size() > 1 ? " (" + LightLabel(light) + ")" : std::string();
  const double radius = 0.5 * options.interior_fraction * white.size;
  const double cos_max = std::cos(options.max_theta_deg * kDegree);
  report->light = light.id;
  report->photos = static_cast<int>(photos.size());
  report->stated = light.has_intensity;
  if (light.has_intensity) report->stated_intensity = light.intensity;
  // The light with unit intensity: its irradiance per unit of intensity at each point.
  Light unit_light = light;
  unit_light.intensity = Eigen::Vector3d::Ones();
  {
    const Incidence incidence = IncidenceAt(unit_light, white.center, white.normal);
    if (!incidence.lit) {
      ThrowError(where, "the white reference faces away from " + LightLabel(light) + " (check its normal)");
    }
  }

  const RadianceReader reader(session);
  std::vector<double> estimates[3];
  for (size_t k : photos) {
    const PhotoSpec& photo = white.photos[k];
    const std::string photo_where = where + "/photos/" + std::to_string(k);
    const std::string path = ResolvePath(session.directory, photo.file);
    if (!photo.camera_from_world)
      ThrowError(photo_where, "white-reference photo " + photo.file + " has no camera_from_world pose");
    const Rigid3d world_from_camera = photo.camera_from_world->Inverse();
    const Eigen::Vector3d camera_center = world_from_camera.translation;
    if ((camera_center - white.center).dot(white.normal) <= 0.0) {
      ThrowError(photo_where, "the camera of " + photo.file + " is behind the white reference");
    }
    const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
    const RadianceImage image = reader.Read({photo}, options.min_signal);
    int box[4];
    DiscBox(session.camera, *photo.camera_from_world, white.center, white.normal, radius, box);
    uint64_t interior = 0, saturated = 0;
    for (int y = box[1]; y < box[3]; ++y) {
      for (int x = box[0]; x < box[2]; ++x) {
        const Eigen::Vector2d xy = session.camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
        const Eigen::Vector3d direction = (rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
        const double cos_e = -direction.dot(white.normal);
        if (!(cos_e > 0.0)) continue;
        const double t = (white.center - camera_center).dot(white.normal) / -cos_e;
        if (!(t > 0.0)) continue;
        const Eigen::Vector3d point = camera_center + t * direction;
        if ((point - white.center).norm() > radius) continue;
        ++interior;
        const size_t p = image.Index(x, y);
        const uint8_t flags = image.flags[p];
        if (flags & kPixelNonFinite) {
          ++report->rejected["non_finite"];
          continue;
        }
        if (flags & kPixelSaturated) {
          ++saturated;
          ++report->rejected["saturated"];
          continue;
        }
        if (flags & kPixelBelowSignal) {
          ++report->rejected["below_signal"];
          continue;
        }
        const Incidence incidence = IncidenceAt(unit_light, point, white.normal);
        if (!(cos_e >= cos_max) || !(incidence.cos_theta >= cos_max)) {
          ++report->rejected["grazing"];
          continue;
        }
        ++report->pixels_used;
        for (int c = 0; c < 3; ++c) {
          estimates[c].push_back(
              LambertianIntensity(image.radiance[3 * p + c], white.reflectance[c], incidence.irradiance[c]));
        }
      }
    }
    report->interior_pixels += interior;
    if (interior > 0 && double(saturated) > options.max_saturated_fraction * double(interior)) {
      char percent[32];
      std::snprintf(percent, sizeof(percent), "%.1f %%", 100.0 * double(saturated) / double(interior));
      ThrowError(path, "the white reference is saturated: " + std::to_string(saturated) + " of its " +
                           std::to_string(interior) + " interior pixels (" + percent +
                           ") are clipped; photograph it with a shorter exposure (" + photo_where + ")");
    }
  }
  if (report->interior_pixels < uint64_t(options.min_pixels)) {
    ThrowError(where, "the white reference is not in view" + label + ": its interior covers " +
                          std::to_string(report->interior_pixels) + " pixel centres in " +
                          std::to_string(photos.size()) + " photos (at least " + std::to_string(options.min_pixels) +
                          " needed; check center, normal, size and the photos' poses)");
  }
  if (report->pixels_used < uint64_t(options.min_pixels)) {
    ThrowError(where, "only " + std::to_string(report->pixels_used) + " of the white reference's " +
                          std::to_string(report->interior_pixels) + " interior pixels are measurable" + label +
                          " (rejected: " + FormatCounts(report->rejected) + "); at least " +
                          std::to_string(options.min_pixels) + " needed");
  }
  for (int c = 0; c < 3; ++c) {
    const double median = Median(estimates[c]);
    if (!(median > 0.0 && std::isfinite(median))) {
      ThrowError(where,
                 "the white reference gives no positive light intensity in channel " + std::to_string(c) + label);
    }
    std::vector<double> deviations(estimates[c].size());
    for (size_t i = 0; i < deviations.size(); ++i) deviations[i] = std::abs(estimates[c][i] - median);
    report->calibrated_intensity[c] = median;
    report->spread[c] = 1.4826 * Median(deviations) / median;
  }
}

}  // namespace

Session ApplyLightCalibration(const Session& session, LightCalibrationReport* report,
                              const LightCalibrationOptions& options) {
  IBRDF_CHECK(report != nullptr);
  Timer timer;
  *report = LightCalibrationReport();
  Session calibrated = session;
  if (!session.calibration || !session.calibration->white_reference) {
    report->success = true;
    return calibrated;
  }
  std::string why;
  if (!options.Check(&why)) ThrowError("light calibration options", why);
  const WhiteReferenceSpec& white = *session.calibration->white_reference;
  if (!white.posed) {
    ThrowError(session.manifest_path + ": /calibration/white_reference",
               "the white reference has no pose (center, normal): run `ibrdf align` on the session first, which "
               "poses it from its card's markers (targets.white_reference), or state center and normal");
  }
  for (size_t k = 0; k < session.lights.size(); ++k) {
    std::vector<size_t> photos;
    for (size_t j = 0; j < white.photos.size(); ++j) {
      if (white.photos[j].light == k) photos.push_back(j);
    }
    if (photos.empty()) continue;
    report->lights.emplace_back();
    CalibrateLight(session, k, photos, options, &report->lights.back());
    calibrated.lights[k].intensity = report->lights.back().calibrated_intensity;
    calibrated.lights[k].has_intensity = true;
  }
  report->photos = static_cast<int>(white.photos.size());
  report->calibrated = true;
  report->verdicts = WhiteReferenceVerdicts(*report);
  report->total_s = timer.ElapsedSeconds();
  report->success = true;
  return calibrated;
}

std::vector<Verdict> WhiteReferenceVerdicts(const LightCalibrationReport& report) {
  constexpr double kWarnSpread = 0.05, kFailSpread = 0.15, kWarnPixels = 1000;
  if (report.lights.empty()) return {};
  const auto label = [](const LightIntensityReport& l) { return l.light.empty() ? std::string("the light") : l.light; };
  const LightIntensityReport* widest = &report.lights.front();
  const LightIntensityReport* fewest = &report.lights.front();
  for (const LightIntensityReport& l : report.lights) {
    if (l.spread.maxCoeff() > widest->spread.maxCoeff()) widest = &l;
    if (l.pixels_used < fewest->pixels_used) fewest = &l;
  }
  char measured[160];
  std::vector<Verdict> verdicts;
  std::snprintf(measured, sizeof(measured), "largest per-pixel spread %.2f %% (%s)", 100.0 * widest->spread.maxCoeff(),
                label(*widest).c_str());
  verdicts.push_back(MakeVerdict(
      "white.spread", widest->spread.maxCoeff(), measured, "warn over 5 %, fail over 15 %",
      VerdictAbove(widest->spread.maxCoeff(), kWarnSpread, kFailSpread),
      "an uneven white reference: check its pose (center, normal; `ibrdf align` from its card's markers), that it "
      "is flat and matte, and the light's position"));
  std::snprintf(measured, sizeof(measured), "%llu pixels used (%s)",
                static_cast<unsigned long long>(fewest->pixels_used), label(*fewest).c_str());
  verdicts.push_back(MakeVerdict("white.pixels", double(fewest->pixels_used), measured, "warn under 1000",
                                 double(fewest->pixels_used) < kWarnPixels ? VerdictLevel::kWarn : VerdictLevel::kOk,
                                 "a larger white reference in the frame, or less of it clipped or too dark"));
  return verdicts;
}

LightCalibrationReport WriteLightCalibrationStage(const Session& session, const LightCalibrationOptions& options,
                                                  const std::string& out_dir, bool overwrite,
                                                  const AcceptedChecks& accept) {
  if (!session.calibration || !session.calibration->white_reference) {
    ThrowError(session.manifest_path, "has no white reference (calibration.white_reference): nothing to calibrate");
  }
  LightCalibrationReport report;
  Session calibrated = ApplyLightCalibration(session, &report, options);
  // Nothing is written when the intensities cannot be trusted, unless the user accepted the check.
  EnforceVerdicts(&report.verdicts, accept, session.manifest_path + ": /calibration/white_reference");
  calibrated.calibration.reset();  // the white reference is its only step, now applied
  calibrated.MarkApplied(SessionStage::kLights);
  AtomicDirectory directory(out_dir, overwrite);
  const std::filesystem::path folder = directory.temporary_path();
  calibrated.Rebased(out_dir).Save((folder / "session.json").string());
  WriteJsonFile((folder / "white-reference.json").string(), report.ToJson());
  directory.Commit();
  return report;
}

}  // namespace ibrdf
