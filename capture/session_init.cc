#include "capture/session_init.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/colour.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/output_guard.h"
#include "core/session.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// "YYYY:MM:DD HH:MM:SS" as seconds since the epoch (UTC; only differences matter); nullopt otherwise.
std::optional<double> CaptureSeconds(const std::string& text) {
  std::tm tm{};
  if (std::sscanf(text.c_str(), "%d:%d:%d %d:%d:%d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &tm.tm_sec) != 6) {
    return std::nullopt;
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(timegm(&tm));
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// The "camera" block of a JSON file (a session, an aligned session, or the block itself).
Camera CameraFromFile(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  const nlohmann::json& block = json.contains("camera") ? json["camera"] : json;
  JsonObject object(block, path, json.contains("camera") ? "/camera" : "");
  CameraModelId model;
  const std::string name = object.String("model");
  if (!CameraModelFromName(name, &model)) ThrowError(object.Where("model"), "unknown camera model \"" + name + "\"");
  const int width = object.Integer("width"), height = object.Integer("height");
  const std::vector<double> params = object.Numbers("params");
  return Camera::Create(model, width, height, params, object.Where());
}

// The "targets" block of a JSON file (what `ibrdf targets` writes, a session, or the block itself).
nlohmann::json TargetsFromFile(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  // `ibrdf targets` writes the ChArUco board's board.json beside targets.json; it has a "dictionary"
  // too, so it would pass for a targets block and fail only in `ibrdf align`.
  if (json.is_object() && json.value("format", "") == "ibrdf-charuco-board") {
    ThrowError(path,
               "is a ChArUco board file (format ibrdf-charuco-board), which calibrates the camera (`ibrdf align "
               "--calibrate DIR`, DIR holding the board's photos and this file), not the markers' layout: pass "
               "--targets the targets.json that `ibrdf targets` wrote beside it");
  }
  const nlohmann::json block = json.contains("targets") ? json["targets"] : json;
  if (!block.is_object() || !block.contains("dictionary")) {
    ThrowError(path, "holds no targets block (an object with \"dictionary\"; `ibrdf targets` writes one)");
  }
  if (!block.contains("reference") && !block.contains("unknown_layout")) {
    ThrowError(path, "holds a targets block without markers (neither \"reference\" nor \"unknown_layout\"); pass "
                     "the targets.json that `ibrdf targets` writes");
  }
  return block;
}

// `path` as the manifest in `out_dir` names it: relative where possible.
std::string RelativeTo(const std::string& path, const std::string& out_dir) {
  const fs::path absolute = fs::absolute(path).lexically_normal();
  const fs::path relative = absolute.lexically_relative(fs::absolute(out_dir).lexically_normal());
  return relative.empty() ? absolute.string() : relative.string();
}

}  // namespace

bool SessionInitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!photos.empty());
  IBRDF_CHECK_OPTION_GE(sensor_width_mm, 0.0);
  IBRDF_CHECK_OPTION_GE(base_iso, 0.0);
  IBRDF_CHECK_OPTION_GE(bracket_size, 0);
  IBRDF_CHECK_OPTION_GT(bracket_gap_s, 0.0);
  IBRDF_CHECK_OPTION_GT(bracket_min_ratio, 1.0);
  IBRDF_CHECK_OPTION(sample_kind == "sphere");
  IBRDF_CHECK_OPTION(response.empty() || response == "linear" || response == "srgb");
  IBRDF_CHECK_OPTION(!sample_radius || *sample_radius > 0.0);
  IBRDF_CHECK_OPTION(!radius_known || sample_radius);
  IBRDF_CHECK_OPTION(!white_size || *white_size > 0.0);
  IBRDF_CHECK_OPTION(!white_reflectance ||
                     ((white_reflectance->array() > 0.0).all() && (white_reflectance->array() <= 1.0).all()));
  IBRDF_CHECK_OPTION(std::all_of(exposure_s.begin(), exposure_s.end(),
                                 [](double t) { return std::isfinite(t) && t > 0.0; }));
  IBRDF_CHECK_OPTION(!chart_corners || !chart_photos.empty());
  IBRDF_CHECK_OPTION(!chart_corners || std::all_of(chart_corners->begin(), chart_corners->end(),
                                                   [](const Eigen::Vector2d& p) { return p.allFinite(); }));
  return true;
}

std::string SessionInitResult::BriefReport() const {
  std::ostringstream out;
  out << "session init: " << photos.size() << " photos";
  if (brackets > 0) out << " (" << brackets << " exposure brackets)";
  out << ", camera from " << camera_source << "; ";
  if (!written) {
    out << "nothing written";
  } else if (complete) {
    out << "complete: " << path;
  } else {
    out << missing.size() << " item(s) missing: " << path;
  }
  return out.str();
}

bool CameraFromMetadata(const PhotoMetadata& m, double sensor_width_mm, Camera* camera, std::string* source) {
  double focal_px = 0.0;
  if (m.focal_length_mm && m.pixels_per_mm) {
    focal_px = *m.focal_length_mm * *m.pixels_per_mm;
    *source = "EXIF focal length " + Format("%.2f mm", *m.focal_length_mm) + " x focal-plane resolution " +
              Format("%.2f px/mm", *m.pixels_per_mm);
  } else if (m.focal_length_mm && sensor_width_mm > 0.0) {
    focal_px = *m.focal_length_mm * m.width / sensor_width_mm;
    *source = "EXIF focal length " + Format("%.2f mm", *m.focal_length_mm) + " on a " +
              Format("%.2f mm", sensor_width_mm) + " wide sensor";
  } else if (m.focal_length_35mm) {
    // The 35 mm equivalent scales the full-frame diagonal (43.27 mm) to the image's.
    focal_px = *m.focal_length_35mm * std::hypot(m.width, m.height) / std::hypot(36.0, 24.0);
    *source = "EXIF 35 mm equivalent focal length " + Format("%.0f mm", *m.focal_length_35mm);
  } else {
    *source = "nothing: the photos carry no focal length with a sensor size";
    return false;
  }
  *camera = Camera::Create(CameraModelId::kPinhole, m.width, m.height,
                           {focal_px, focal_px, 0.5 * m.width, 0.5 * m.height}, "camera from EXIF");
  return true;
}

int GroupBrackets(const SessionInitOptions& options, std::vector<InitPhoto>* photos) {
  int next = 0, brackets = 0;
  int size = 0;       // exposures in the open bracket
  int direction = 0;  // +1 lengthening, -1 shortening exposures in the open bracket
  const InitPhoto* previous = nullptr;
  for (InitPhoto& photo : *photos) {
    if (photo.target || photo.white || photo.chart) continue;
    bool join = false;
    if (previous && options.bracket_size > 1) {
      join = size < options.bracket_size;
    } else if (previous && options.bracket_size == 0) {
      const double a = *previous->metadata.exposure_s * previous->gain, b = *photo.metadata.exposure_s * photo.gain;
      const double ratio = b / a;
      const int step = ratio >= options.bracket_min_ratio ? 1 : 1.0 / ratio >= options.bracket_min_ratio ? -1 : 0;
      const std::optional<double> t0 = CaptureSeconds(previous->metadata.date_time);
      const std::optional<double> t1 = CaptureSeconds(photo.metadata.date_time);
      const bool burst = !t0 || !t1 || std::abs(*t1 - *t0) <= options.bracket_gap_s;
      // A photo without EXIF has no capture time either: nothing says it shares the previous one's pose.
      const bool exif = !previous->exposure_given && !photo.exposure_given;
      join = step != 0 && burst && exif && (direction == 0 || step == direction);
      if (join) direction = step;
    }
    if (join) {
      photo.bracket = previous->bracket;
      if (++size == 2) ++brackets;
    } else {
      photo.bracket = next++;
      size = 1;
      direction = 0;
    }
    previous = &photo;
  }
  if (options.bracket_size > 1 && size != options.bracket_size && previous) {
    ThrowError(previous->file, "the last bracket has " + std::to_string(size) + " exposures, not --bracket-size " +
                                   std::to_string(options.bracket_size));
  }
  // Single photos are no bracket: drop their ids.
  std::vector<int> count(next, 0);
  for (const InitPhoto& photo : *photos) {
    if (photo.bracket >= 0) ++count[photo.bracket];
  }
  for (InitPhoto& photo : *photos) {
    if (photo.bracket >= 0 && count[photo.bracket] < 2) photo.bracket = -1;
  }
  return brackets;
}

namespace {

// Every photo's metadata, in the manifest's order (measurement, target, white-reference and chart photos);
// one size for all and an exposure time for each.
void ReadPhotos(const SessionInitOptions& options, SessionInitResult* result) {
  for (int pass = 0; pass < 4; ++pass) {
    for (const std::string& file : pass == 0   ? options.photos
                                   : pass == 1 ? options.target_photos
                                   : pass == 2 ? options.white_photos
                                               : options.chart_photos) {
      InitPhoto photo;
      photo.file = file;
      photo.metadata = ReadPhotoMetadata(file);
      photo.target = pass == 1;
      photo.white = pass == 2;
      photo.chart = pass == 3;
      result->photos.push_back(photo);
    }
  }
  const InitPhoto& first = result->photos.front();
  std::vector<std::string> no_exposure;
  for (const InitPhoto& photo : result->photos) {
    if (photo.metadata.width != first.metadata.width || photo.metadata.height != first.metadata.height) {
      ThrowError(photo.file, "is " + std::to_string(photo.metadata.width) + "x" +
                                 std::to_string(photo.metadata.height) + ", " + first.file + " is " +
                                 std::to_string(first.metadata.width) + "x" + std::to_string(first.metadata.height) +
                                 ": one session, one camera");
    }
  }
  const size_t given = options.exposure_s.size();
  if (given > 1 && given != result->photos.size()) {
    ThrowError("--exposure-s", "has " + std::to_string(given) + " values; give one (every photo without an EXIF "
                               "exposure time) or one per photo (" + std::to_string(result->photos.size()) +
                               ": the photos, then --target-photos, --white-photos, --chart-photos, in that order)");
  }
  // The exposure time: EXIF's, else --exposure-s (stated as assumed, since nothing checks it).
  std::vector<std::string> assumed;
  for (size_t k = 0; k < result->photos.size(); ++k) {
    InitPhoto& photo = result->photos[k];
    if (photo.metadata.exposure_s) continue;
    if (given == 0) {
      no_exposure.push_back(photo.file);
    } else {
      photo.metadata.exposure_s = options.exposure_s[given == 1 ? 0 : k];
      photo.exposure_given = true;
      assumed.push_back(photo.file);
    }
  }
  const auto listed = [](const std::vector<std::string>& files) {
    std::string list;
    for (size_t i = 0; i < files.size() && i < 5; ++i) list += (i ? ", " : "") + files[i];
    if (files.size() > 5) list += ", ...";
    return list;
  };
  if (!no_exposure.empty()) {
    ThrowError(no_exposure.front(),
               std::to_string(no_exposure.size()) + " photo(s) carry no EXIF exposure time (" + listed(no_exposure) +
                   "); pass --exposure-s S (seconds, every photo without one) or S1,S2,... (one per photo)");
  }
  if (!assumed.empty()) {
    result->assumptions.push_back(
        (given == 1 ? "exposure time " + Format("%g s", options.exposure_s[0]) + " (--exposure-s, as given)"
                    : std::string("exposure times one per photo (--exposure-s, as given)")) +
        " for " + std::to_string(assumed.size()) + " photo(s) without an EXIF exposure time: " + listed(assumed) +
        (assumed.size() < result->photos.size() ? "; the others' come from their EXIF" : "") +
        "; these photos form exposure brackets only with --bracket-size");
  }
}

// Each photo's gain, ISO over the base ISO (--base-iso, else the lowest ISO among the photos).
void AssignGains(const SessionInitOptions& options, SessionInitResult* result) {
  double lowest_iso = 0.0;
  for (const InitPhoto& photo : result->photos) {
    if (photo.metadata.iso && (lowest_iso == 0.0 || *photo.metadata.iso < lowest_iso)) lowest_iso = *photo.metadata.iso;
  }
  const double base_iso = options.base_iso > 0.0 ? options.base_iso : lowest_iso;
  bool some_iso_missing = false;
  for (InitPhoto& photo : result->photos) {
    if (photo.metadata.iso && base_iso > 0.0) {
      photo.gain = *photo.metadata.iso / base_iso;
    } else {
      some_iso_missing = true;
    }
  }
  if (base_iso > 0.0) {
    result->assumptions.push_back("gain = ISO / " + Format("%g", base_iso) +
                                  (options.base_iso > 0.0 ? " (--base-iso)" : " (the lowest ISO among the photos)"));
  }
  if (some_iso_missing) result->assumptions.push_back("photos without an EXIF ISO have gain 1");
}

// The camera: the calibration file given, else a pinhole guess from EXIF; nullopt (and a missing
// entry) when neither is there.
std::optional<Camera> ResolveCamera(const SessionInitOptions& options, const PhotoMetadata& first,
                                    SessionInitResult* result) {
  std::optional<Camera> camera;
  if (!options.camera_file.empty()) {
    camera = CameraFromFile(options.camera_file);
    result->camera_source = "calibration " + options.camera_file;
    if (camera->width != first.width || camera->height != first.height) {
      ThrowError(options.camera_file, "the camera is " + std::to_string(camera->width) + "x" +
                                          std::to_string(camera->height) + ", the photos " +
                                          std::to_string(first.width) + "x" + std::to_string(first.height));
    }
  } else {
    Camera guess;
    if (CameraFromMetadata(first, options.sensor_width_mm, &guess, &result->camera_source)) {
      camera = guess;
      result->assumptions.push_back(
          "camera: a pinhole guess (no distortion, principal point at the centre) from " + result->camera_source +
          "; calibrate it with `ibrdf align --calibrate BOARD_DIR` (ChArUco photos) or pass --camera");
    } else {
      result->missing.push_back("the camera: pass --camera FILE (a calibrated camera block) or --sensor-width-mm");
    }
  }
  if (camera) result->camera = *camera;
  return camera;
}

// The manifest's description: how many photos, the camera's make and model, the f-number.
std::string Description(const SessionInitResult& result) {
  const PhotoMetadata& first = result.photos.front().metadata;
  std::string description = "Drafted by `ibrdf session init` from " + std::to_string(result.photos.size()) + " photos";
  if (!first.make.empty() || !first.model.empty()) description += " (" + first.make + " " + first.model + ")";
  if (first.f_number) description += ", f/" + Format("%g", *first.f_number);
  return description;
}

// The one point light: position and intensity as given, placeholders where a later stage measures
// them (markers on the light, the white reference), null and a missing entry otherwise.
nlohmann::json LightJson(const SessionInitOptions& options, bool light_markers, SessionInitResult* result) {
  nlohmann::json light = {{"kind", LightKindName(Light::Kind::kPoint)}};
  if (options.light_position) {
    light["position"] = ToJson(*options.light_position);
  } else if (light_markers) {
    light["position"] = "unknown";
    result->assumptions.push_back("light position: unknown; `ibrdf align` finds the light from its markers");
  } else {
    light["position"] = nullptr;
    result->missing.push_back(
        "the light's position (metres, the targets' frame): pass --light-position-m X Y Z or put markers on the "
        "light (`ibrdf targets` prints its card)");
  }
  if (options.light_intensity) {
    light["intensity"] = ToJson(*options.light_intensity);
  } else if (!options.white_photos.empty()) {
    result->assumptions.push_back("light intensity: none stated; the white reference measures it (ibrdf derender)");
  } else {
    light["intensity"] = nullptr;
    result->missing.push_back(
        "the light's RGB intensity in the session's radiance unit: pass --light-intensity R,G,B (a white "
        "reference photo measures it: docs/capture.md)");
  }
  return light;
}

// The sample: its radius and centre as given; with targets, the centre of a sphere resting on the platform.
nlohmann::json SampleJson(const SessionInitOptions& options, bool has_targets, SessionInitResult* result) {
  nlohmann::json sample = {{"kind", options.sample_kind}};
  if (options.sample_radius) {
    sample["radius"] = *options.sample_radius;
    if (options.radius_known) sample["radius_known"] = true;
  } else {
    sample["radius"] = nullptr;
    result->missing.push_back(
        "the sphere's radius (metres): pass --sample-radius-m R (and --radius-known if measured)");
  }
  if (options.sample_center) {
    sample["center"] = ToJson(*options.sample_center);
  } else if (has_targets && options.sample_radius) {
    sample["center"] = {0.0, 0.0, *options.sample_radius};
    result->assumptions.push_back(
        "sphere centre: resting on the platform's centre, (0, 0, radius); `ibrdf align` fits it from the silhouettes");
  } else {
    sample["center"] = nullptr;
    result->missing.push_back("the sphere's centre (metres, the targets' frame): pass --sample-center-m X Y Z");
  }
  return sample;
}

// The response (--response, else linear for RAW, float and deep photos, sRGB for 8-bit ones) and black level 0.
nlohmann::json RadiometryJson(const SessionInitOptions& options, const PhotoMetadata& first,
                              SessionInitResult* result) {
  std::string response = options.response;
  if (response.empty()) {
    const bool linear_file = first.raw || first.floating_point || first.bits > 8;
    response = linear_file ? "linear" : "srgb";
    result->assumptions.push_back("response \"" + response + "\" (" +
                                  (first.raw              ? std::string("camera RAW decodes linearly")
                                   : first.floating_point ? std::string("floating-point photos")
                                   : first.bits > 8       ? std::to_string(first.bits) + "-bit photos, taken as linear"
                                                          : std::string("8-bit photos, taken as sRGB-encoded")) +
                                  "); pass --response or calibrate the response if it is not");
  }
  result->assumptions.push_back(
      "black level 0 and no saturation level stated (integer photos clip at full scale, float photos never; "
      "camera RAW: the file's black and white levels are applied when decoding)");
  return {{"response", response}, {"black_level", 0.0}};
}

// The colour chart: its photos (exposure and gain from EXIF like the others) and, when given, its
// corner patches; `ibrdf colour` fits the matrix (and detects the chart without corners).
nlohmann::json ColourChartJson(const SessionInitOptions& options, const nlohmann::json& chart_photos,
                               SessionInitResult* result) {
  nlohmann::json chart = {{"chart", kColorCheckerClassic24},
                          {"space", ColourSpaceName(ColourSpace::kLinearSrgb)},
                          {"photos", chart_photos}};
  if (options.chart_corners) {
    for (const Eigen::Vector2d& p : *options.chart_corners) chart["corners"].push_back({p.x(), p.y()});
  }
  result->assumptions.push_back(
      "colour chart: a ColorChecker Classic 24 under the session's light, corrected into linear sRGB; " +
      std::string(options.chart_corners ? "located by the corner patches given"
                                        : "no corner patches given, so `ibrdf colour` detects it (OpenCV mcc)") +
      "; run `ibrdf colour` on the session to fit its matrix before `ibrdf derender`");
  return chart;
}

// The white reference: posed by `ibrdf align` from the white card's markers, when the targets have them.
nlohmann::json WhiteReferenceJson(const SessionInitOptions& options, const nlohmann::json& white_photos,
                                  bool white_card_markers, SessionInitResult* result) {
  nlohmann::json white = {{"photos", white_photos}};
  white["reflectance"] = ToJson(options.white_reflectance.value_or(Eigen::Vector3d::Constant(0.99)));
  if (!options.white_reflectance) {
    result->assumptions.push_back("white reference reflectance 0.99 (Spectralon's); pass --white-reflectance R,G,B");
  }
  if (options.white_size) {
    white["size"] = *options.white_size;
  } else {
    white["size"] = nullptr;
    result->missing.push_back("the white reference's size (metres, the patch's side): pass --white-size-m S");
  }
  if (!white_card_markers) {
    white["center"] = nullptr;
    white["normal"] = nullptr;
    result->missing.push_back(
        "the white reference's centre and normal: print the white card (`ibrdf targets`), mount the reference on "
        "it and pass its targets.json with --targets (`ibrdf align` then poses it), or state them by hand");
  }
  return white;
}

// Writes session.json when the manifest validates, else session.draft.json with the missing list.
void WriteManifest(const SessionInitOptions& options, const std::string& out_dir, nlohmann::json json,
                   SessionInitResult* result) {
  const std::string session_path = (fs::path(out_dir) / "session.json").string();
  const std::string draft_path = (fs::path(out_dir) / "session.draft.json").string();
  // The manifest lands beside the photos when --out is their folder; never on one of the inputs (a
  // camera or targets file named session.json), --overwrite or not.
  std::vector<std::string> inputs = {options.camera_file, options.targets_file};
  for (const auto* files : {&options.photos, &options.target_photos, &options.white_photos, &options.chart_photos}) {
    inputs.insert(inputs.end(), files->begin(), files->end());
  }
  if (fs::exists(out_dir) && !fs::is_directory(out_dir)) {
    ThrowError(out_dir, "is a file (--out: the folder to write session.json in)");
  }
  for (const std::string& path : {session_path, draft_path}) {
    RequireOutputOutsideInputs(path, inputs);
    if (fs::exists(path) && !options.overwrite) ThrowError(path, "exists; pass --overwrite to replace it");
  }
  fs::create_directories(out_dir);
  if (result->missing.empty()) {
    const std::string trial = (fs::path(out_dir) / ".session.init.json").string();
    WriteJsonFile(trial, json);
    try {
      Session::Load(trial);
      fs::rename(trial, session_path);
      if (fs::exists(draft_path)) fs::remove(draft_path);
      result->complete = true;
      result->path = session_path;
    } catch (const Error& e) {
      fs::remove(trial);
      result->missing.push_back(std::string("the draft does not validate: ") + e.what());
    }
  }
  if (!result->complete) {
    json["missing"] = result->missing;
    WriteJsonFile(draft_path, json);
    result->path = draft_path;
  }
  result->written = true;
}

}  // namespace

SessionInitResult InitSession(const SessionInitOptions& options, const std::string& out_dir) {
  std::string why;
  if (!options.Check(&why)) ThrowError("session init options", why);
  SessionInitResult result;
  ReadPhotos(options, &result);
  AssignGains(options, &result);
  result.brackets = GroupBrackets(options, &result.photos);
  const PhotoMetadata& first = result.photos.front().metadata;
  const std::optional<Camera> camera = ResolveCamera(options, first, &result);

  nlohmann::json json;
  json["format"] = "ibrdf-session";
  json["version"] = 1;
  json["name"] = options.name.empty() ? fs::path(out_dir).filename().string() : options.name;
  json["description"] = Description(result);
  if (camera) {
    json["camera"] = {{"model", CameraModelName(camera->model)},
                      {"width", camera->width},
                      {"height", camera->height},
                      {"params", camera->params}};
  } else {
    json["camera"] = nullptr;
  }
  bool light_markers = false;
  if (!options.targets_file.empty()) {
    json["targets"] = TargetsFromFile(options.targets_file);
    light_markers = json["targets"].contains("light");
  }
  json["light"] = LightJson(options, light_markers, &result);
  json["sample"] = SampleJson(options, json.contains("targets"), &result);
  json["radiometry"] = RadiometryJson(options, first, &result);
  nlohmann::json photos = nlohmann::json::array(), white_photos = nlohmann::json::array(),
                 chart_photos = nlohmann::json::array();
  for (const InitPhoto& photo : result.photos) {
    nlohmann::json entry = {{"file", RelativeTo(photo.file, out_dir)}, {"exposure_s", *photo.metadata.exposure_s}};
    if (photo.gain != 1.0) entry["gain"] = photo.gain;
    if (photo.target) entry["role"] = "targets";
    if (photo.bracket >= 0) entry["bracket"] = photo.bracket;
    (photo.white ? white_photos : photo.chart ? chart_photos : photos).push_back(entry);
  }
  json["photos"] = photos;
  if (!chart_photos.empty()) json["colour_chart"] = ColourChartJson(options, chart_photos, &result);
  if (!white_photos.empty()) {
    const bool white_card_markers = json.contains("targets") && json["targets"].contains("white_reference");
    json["calibration"] = {{"white_reference", WhiteReferenceJson(options, white_photos, white_card_markers, &result)}};
  }
  if (!json.contains("targets")) {
    result.missing.push_back(
        "the photos' poses: pass --targets FILE (the markers' layout from `ibrdf targets`) and run `ibrdf align`, "
        "or add camera_from_world poses by hand");
  }
  WriteManifest(options, out_dir, std::move(json), &result);
  return result;
}

}  // namespace ibrdf
