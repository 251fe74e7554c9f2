#include "core/session.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/light_json.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// A marker's "corners": four finite [x, y, z] points in OpenCV's order.
std::array<Eigen::Vector3d, 4> MarkerCorners(JsonObject& marker) {
  const nlohmann::json& corners = marker.Raw("corners");
  if (!corners.is_array() || corners.size() != 4) {
    ThrowError(marker.Where("corners"),
               "expected 4 corners [[x, y, z] x 4] (top-left, top-right, bottom-right, bottom-left)");
  }
  std::array<Eigen::Vector3d, 4> points;
  for (int k = 0; k < 4; ++k) {
    const nlohmann::json& c = corners[k];
    const std::string where = marker.Where("corners") + "/" + std::to_string(k);
    if (!c.is_array() || c.size() != 3 || !c[0].is_number() || !c[1].is_number() || !c[2].is_number()) {
      ThrowError(where, "expected [x, y, z]");
    }
    points[k] = Eigen::Vector3d(c[0].get<double>(), c[1].get<double>(), c[2].get<double>());
    if (!points[k].allFinite()) ThrowError(where, "expected finite numbers");
  }
  return points;
}

constexpr char kFormat[] = "ibrdf-session";
constexpr int kVersion = 2;  // written; versions 1 and 2 are read

void RequirePositive(JsonObject& object, const std::string& key, double value) {
  if (!(value > 0.0)) ThrowError(object.Where(key), "must be positive, got " + std::to_string(value));
}

Camera ParseCamera(JsonObject object) {
  const std::string model_name = object.String("model");
  CameraModelId model;
  if (!CameraModelFromName(model_name, &model)) {
    ThrowError(object.Where("model"), "unsupported camera model \"" + model_name +
                                          "\" (expected SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, "
                                          "RADIAL or OPENCV)");
  }
  const int width = object.Integer("width");
  const int height = object.Integer("height");
  std::vector<double> params = object.Numbers("params");
  object.Finish();
  return Camera::Create(model, width, height, std::move(params), object.Where());
}

// A light object: the single `light` (any version) or an entry of version 2's `lights` (which needs
// an id). Version 2 lets a light leave out its intensity when a calibration measures it (checked once
// the calibration block is read).
Light ParseLight(JsonObject object, int version, bool needs_id) {
  Light light;
  if (version >= 2 && (needs_id || object.Has("id"))) {
    light.id = object.String("id");
    if (light.id.empty()) ThrowError(object.Where("id"), "a light's id must not be empty");
  }
  const std::string kind = object.String("kind");
  if (kind == "point") {
    light.kind = Light::Kind::kPoint;
    if (object.Has("position") && object.Raw("position") == "unknown") {
      light.placement_known = false;
    } else {
      light.position = object.Vector3("position");
    }
  } else if (kind == "directional") {
    light.kind = Light::Kind::kDirectional;
    light.direction = object.Vector3("direction");
    if (!(light.direction.norm() > 0.0)) ThrowError(object.Where("direction"), "must be non-zero");
    light.direction.normalize();
  } else {
    ThrowError(object.Where("kind"), "unknown light kind \"" + kind + "\" (expected point or directional)");
  }
  if (!object.Has("intensity")) {
    light.has_intensity = false;
  } else {
    light.intensity = object.Vector3("intensity");
    if ((light.intensity.array() < 0.0).any() || !(light.intensity.maxCoeff() > 0.0)) {
      ThrowError(object.Where("intensity"), "must be non-negative and not all zero");
    }
  }
  object.Finish();
  return light;
}

// "L01, L02, L03" for messages (at most 12 ids shown).
std::string LightIds(const std::vector<Light>& lights) {
  std::string ids;
  for (size_t k = 0; k < lights.size() && k < 12; ++k) ids += (k ? ", " : "") + lights[k].id;
  if (lights.size() > 12) ids += ", ... (" + std::to_string(lights.size()) + " lights)";
  return ids;
}

// What a photo's keys are checked against: the manifest's version and its lights.
struct PhotoContext {
  int version = 1;
  const std::vector<Light>* lights = nullptr;
  bool white_reference = false;  // a white-reference photo (no role, no mask)
  bool white_card = false;       // the targets carry the white reference's markers (its pose may be left out)
};

// A photo's (or a light-marker block's) `light`: the id of one of the session's lights. With one light
// the key may be left out; with several it is required (`required`, for photos that are lit).
size_t ParseLightReference(JsonObject& object, const std::vector<Light>& lights, bool required,
                           const std::string& what) {
  if (!object.Has("light")) {
    if (lights.size() == 1 || !required) return 0;
    ThrowError(object.Where("light"), what + " must name its light: the session has " + std::to_string(lights.size()) +
                                          " (" + LightIds(lights) + ")");
  }
  const std::string id = object.String("light");
  for (size_t k = 0; k < lights.size(); ++k) {
    if (lights[k].id == id && !id.empty()) return k;
  }
  if (lights.size() == 1 && lights[0].id.empty()) {
    ThrowError(object.Where("light"), what + " names light \"" + id +
                                          "\" but the session's one light has no id (give it \"id\": \"" + id +
                                          "\", or leave the photo's light out)");
  }
  ThrowError(object.Where("light"), what + " names light \"" + id +
                                        "\", which the session does not have (its lights: " + LightIds(lights) + ")");
}

Rigid3d ParsePose(JsonObject object);

// The keys of a mesh sample (docs/session-format.md). The mesh file is not opened here: the scan
// stage may write it after the session; the derenderer reports a missing or broken one.
void ParseMeshSample(JsonObject& object, SampleSpec* sample) {
  sample->kind = SampleSpec::Kind::kMesh;
  sample->mesh_file = object.String("file");
  if (sample->mesh_file.empty()) ThrowError(object.Where("file"), "must name the mesh file");
  if (object.Has("world_from_mesh")) {
    sample->world_from_mesh = Sim3dFromJson(object.Raw("world_from_mesh"), object.file(), "/sample/world_from_mesh");
  }
  if (object.Has("scan_inputs")) {
    const nlohmann::json& inputs = object.Raw("scan_inputs");
    if (!inputs.is_array()) ThrowError(object.Where("scan_inputs"), "expected an array, got " + JsonTypeName(inputs));
    for (size_t i = 0; i < inputs.size(); ++i) {
      const std::string pointer = "/sample/scan_inputs/" + std::to_string(i);
      ScanInputSpec input;
      if (inputs[i].is_string()) {
        input.file = inputs[i].get<std::string>();
      } else if (inputs[i].is_object()) {
        JsonObject entry(inputs[i], object.file(), pointer);
        input.file = entry.String("file");
        if (entry.Has("world_from_scan")) input.world_from_scan = ParsePose(entry.Object("world_from_scan"));
        entry.Finish();
      } else {
        ThrowError(object.file() + ": " + pointer,
                   "expected a file name or {\"file\", \"world_from_scan\"}, got " + JsonTypeName(inputs[i]));
      }
      if (input.file.empty()) ThrowError(object.file() + ": " + pointer, "empty file name");
      sample->scan_inputs.push_back(input);
    }
  }
  if (object.Has("scan_targets")) {
    std::set<int> seen;
    for (JsonObject& marker : object.Objects("scan_targets")) {
      ScanTargetSpec target;
      target.id = marker.Integer("id");
      if (target.id < 0) ThrowError(marker.Where("id"), "marker ids are non-negative");
      if (!seen.insert(target.id).second) {
        ThrowError(marker.Where("id"), "marker id " + std::to_string(target.id) + " is listed twice");
      }
      target.corners = MarkerCorners(marker);
      marker.Finish();
      sample->scan_targets.push_back(target);
    }
  }
  const std::string visibility = object.String("visibility", "auto");
  if (!VisibilityFromName(visibility, &sample->visibility)) {
    ThrowError(object.Where("visibility"), "unknown visibility \"" + visibility + "\" (expected auto, on or off)");
  }
}

SampleSpec ParseSample(JsonObject object) {
  SampleSpec sample;
  const std::string kind = object.String("kind");
  if (kind == "sphere") {
    sample.kind = SampleSpec::Kind::kSphere;
    sample.center = object.Vector3("center");
    sample.radius = object.Number("radius");
    RequirePositive(object, "radius", sample.radius);
    sample.radius_known = object.Boolean("radius_known", false);
  } else if (kind == "cylinder") {
    sample.kind = SampleSpec::Kind::kCylinder;
    sample.center = object.Vector3("center");
    sample.axis = object.Vector3("axis");
    if (!(sample.axis.norm() > 0.0)) ThrowError(object.Where("axis"), "must be non-zero");
    sample.axis.normalize();
    sample.radius = object.Number("radius");
    RequirePositive(object, "radius", sample.radius);
    sample.length = object.Number("length");
    RequirePositive(object, "length", sample.length);
  } else if (kind == "mesh") {
    ParseMeshSample(object, &sample);
  } else {
    ThrowError(object.Where("kind"), "unknown sample kind \"" + kind + "\" (expected sphere, cylinder or mesh)");
  }
  object.Finish();
  return sample;
}

Response ParseResponse(JsonObject& parent) {
  Response response;
  const nlohmann::json& value = parent.Raw("response");
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    if (name == "linear") {
      response.kind = Response::Kind::kLinear;
    } else if (name == "srgb") {
      response.kind = Response::Kind::kSrgb;
    } else if (name == "unknown") {
      response.kind = Response::Kind::kUnknown;
    } else {
      ThrowError(parent.Where("response"), "unknown response \"" + name +
                                               "\" (expected \"linear\", \"srgb\", \"unknown\", {\"gamma\": g} "
                                               "or {\"table\": [...]})");
    }
  } else if (value.is_object()) {
    JsonObject object = parent.Object("response");
    if (object.Has("gamma")) {
      response.kind = Response::Kind::kGamma;
      response.gamma = object.Number("gamma");
    } else if (object.Has("table")) {
      response.kind = Response::Kind::kTable;
      response.table = object.Numbers("table");
      if (object.Has("uncertainty")) response.uncertainty = object.Numbers("uncertainty");
    } else {
      ThrowError(parent.Where("response"), "expected {\"gamma\": g} or {\"table\": [...]}");
    }
    object.Finish();
  } else {
    ThrowError(parent.Where("response"), "expected a string or an object, got " + JsonTypeName(value));
  }
  std::string why;
  if (!response.Check(&why)) ThrowError(parent.Where("response"), why);
  return response;
}

RadiometrySpec ParseRadiometry(JsonObject object, const std::string& directory) {
  RadiometrySpec radiometry;
  if (object.Has("response")) radiometry.response = ParseResponse(object);
  radiometry.black_level = object.Number("black_level", 0.0);
  radiometry.saturation_stated = object.Has("saturation_level");
  radiometry.saturation_level = object.Number("saturation_level", 1.0);
  if (radiometry.black_level < 0.0) ThrowError(object.Where("black_level"), "must not be negative");
  if (!(radiometry.saturation_level > radiometry.black_level)) {
    ThrowError(object.Where("saturation_level"), "must be above black_level");
  }
  if (object.Has("noise")) {
    JsonObject noise_object = object.Object("noise");
    CameraNoise noise;
    noise.full_well_e = noise_object.Number("full_well_e");
    RequirePositive(noise_object, "full_well_e", noise.full_well_e);
    noise.read_noise_e = noise_object.Number("read_noise_e");
    if (noise.read_noise_e < 0.0) ThrowError(noise_object.Where("read_noise_e"), "must not be negative");
    noise.bits = noise_object.Integer("bits", 0);
    if (noise.bits < 0 || noise.bits > 32) ThrowError(noise_object.Where("bits"), "expected 0 to 32");
    noise_object.Finish();
    radiometry.noise = noise;
  }
  const std::string scale = object.String("intensity_scale", "absolute");
  if (scale != "absolute" && scale != "relative") {
    ThrowError(object.Where("intensity_scale"), "expected \"absolute\" or \"relative\", got \"" + scale + "\"");
  }
  radiometry.relative_intensities = scale == "relative";
  if (object.Has("flat_field")) {
    radiometry.flat_field = object.String("flat_field");
    const std::string path = ResolvePath(directory, radiometry.flat_field);
    if (!fs::is_regular_file(path))
      ThrowError(object.Where("flat_field"), "flat-field image " + path + " does not exist");
  }
  object.Finish();
  return radiometry;
}

Rigid3d ParsePose(JsonObject object) {
  const std::vector<double> q = object.Numbers("rotation");
  if (q.size() != 4) ThrowError(object.Where("rotation"), "expected a quaternion [qw, qx, qy, qz]");
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-6) {
    ThrowError(object.Where("rotation"), "quaternion is not unit length (norm " + std::to_string(norm) + ")");
  }
  Rigid3d pose;
  pose.rotation = Eigen::Quaterniond(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  pose.translation = object.Vector3("translation");
  object.Finish();
  return pose;
}

PhotoSpec ParsePhoto(JsonObject object, const std::string& directory, const PhotoContext& context) {
  PhotoSpec photo;
  photo.file = object.String("file");
  photo.exposure_s = object.Number("exposure_s");
  RequirePositive(object, "exposure_s", photo.exposure_s);
  photo.gain = object.Number("gain", 1.0);
  RequirePositive(object, "gain", photo.gain);
  if (object.Has("camera_from_world")) photo.camera_from_world = ParsePose(object.Object("camera_from_world"));
  const std::string role = object.String("role", "measurement");
  if (role == "targets") {
    photo.role = PhotoRole::kTargets;
  } else if (role != "measurement") {
    ThrowError(object.Where("role"), "unknown role \"" + role + "\" (expected \"measurement\" or \"targets\")");
  }
  if (object.Has("bracket")) {
    photo.bracket = object.Integer("bracket");
    if (*photo.bracket < 0) ThrowError(object.Where("bracket"), "bracket ids are non-negative");
  }
  if (context.version < 2) {
    for (const char* key : {"light", "mask"}) {
      if (object.Has(key)) {
        ThrowError(object.Where(key),
                   std::string("a photo's \"") + key + "\" needs \"version\": 2 (this manifest is version 1)");
      }
    }
  } else {
    photo.light = ParseLightReference(object, *context.lights, photo.role == PhotoRole::kMeasurement, "the photo");
    if (object.Has("mask")) {
      if (context.white_reference) ThrowError(object.Where("mask"), "a white-reference photo takes no mask");
      if (photo.role == PhotoRole::kTargets) {
        ThrowError(object.Where("mask"), "a targets photo is not derendered; masks apply to measurement photos");
      }
      photo.mask = object.String("mask");
      if (photo.mask.empty()) ThrowError(object.Where("mask"), "empty file name");
      const std::string mask_path = ResolvePath(directory, photo.mask);
      if (!fs::is_regular_file(mask_path)) ThrowError(object.Where("mask"), "mask " + mask_path + " does not exist");
    }
  }
  const std::string path = ResolvePath(directory, photo.file);
  if (!fs::is_regular_file(path)) ThrowError(object.Where("file"), "photo " + path + " does not exist");
  object.Finish();
  return photo;
}

TargetsSpec ParseTargets(JsonObject object, const std::vector<Light>& lights) {
  TargetsSpec targets;
  targets.dictionary = object.String("dictionary");
  std::set<int> seen;
  auto marker_id = [&seen](JsonObject& marker) {
    const int id = marker.Integer("id");
    if (id < 0) ThrowError(marker.Where("id"), "marker ids are non-negative");
    if (!seen.insert(id).second) ThrowError(marker.Where("id"), "marker id " + std::to_string(id) + " is listed twice");
    return id;
  };
  auto marker_corners = [&](JsonObject& marker) {
    TargetSpec target;
    target.id = marker_id(marker);
    target.corners = MarkerCorners(marker);
    marker.Finish();
    return target;
  };
  if (object.Has("reference") || !object.Has("unknown_layout")) {
    for (JsonObject& marker : object.Objects("reference")) targets.reference.push_back(marker_corners(marker));
  }
  if (object.Has("unknown_layout")) {
    JsonObject layout = object.Object("unknown_layout");
    UnknownLayoutSpec spec;
    spec.size = layout.Number("size");
    RequirePositive(layout, "size", spec.size);
    const std::vector<double> ids = layout.Numbers("ids");
    if (ids.empty()) ThrowError(layout.Where("ids"), "expected at least one marker id");
    for (size_t k = 0; k < ids.size(); ++k) {
      const std::string where = layout.Where("ids") + "/" + std::to_string(k);
      if (!(ids[k] >= 0.0) || ids[k] != std::floor(ids[k]) || ids[k] > 1e6)
        ThrowError(where, "expected a non-negative integer id");
      if (!seen.insert(int(ids[k])).second)
        ThrowError(where, "marker id " + std::to_string(int(ids[k])) + " is listed twice");
      spec.ids.push_back(int(ids[k]));
    }
    if (layout.Has("origin_id")) {
      spec.origin_id = layout.Integer("origin_id");
      if (!targets.reference.empty()) {
        ThrowError(layout.Where("origin_id"),
                   "the known-layout markers in /targets/reference already fix the world frame; drop origin_id");
      }
      if (std::find(spec.ids.begin(), spec.ids.end(), *spec.origin_id) == spec.ids.end()) {
        ThrowError(layout.Where("origin_id"), "marker " + std::to_string(*spec.origin_id) + " is not in ids");
      }
    } else if (targets.reference.empty()) {
      ThrowError(
          layout.Where("origin_id"),
          "without known-layout markers (/targets/reference) one marker must fix the world frame: give origin_id");
    }
    layout.Finish();
    targets.unknown_layout = spec;
  }
  if (object.Has("sample")) {
    JsonObject sample = object.Object("sample");
    SampleTargetsSpec spec;
    for (JsonObject& marker : sample.Objects("markers")) {
      const std::string where = marker.Where("corners");
      const TargetSpec target = marker_corners(marker);
      const double side = (target.corners[1] - target.corners[0]).norm();
      for (int k = 0; k < 4; ++k) {
        const double edge = (target.corners[(k + 1) % 4] - target.corners[k]).norm();
        if (!(side > 0.0) || std::abs(edge - side) > 1e-3 * side ||
            std::abs((target.corners[(k + 1) % 4] - target.corners[k])
                         .dot(target.corners[(k + 2) % 4] - target.corners[(k + 1) % 4])) > 1e-3 * side * side) {
          ThrowError(where, "the corners are not a square (sides and right angles within 0.1 %)");
        }
      }
      spec.markers.push_back(target);
    }
    if (spec.markers.empty()) ThrowError(sample.Where("markers"), "expected at least one marker on the sample");
    sample.Finish();
    targets.sample = spec;
  }
  if (object.Has("white_reference")) {
    JsonObject card = object.Object("white_reference");
    WhiteReferenceTargetsSpec spec;
    for (JsonObject& marker : card.Objects("markers")) spec.markers.push_back(marker_corners(marker));
    if (spec.markers.empty()) ThrowError(card.Where("markers"), "expected at least one marker on the white reference");
    card.Finish();
    targets.white_reference = spec;
  }
  if (object.Has("light")) {
    JsonObject light = object.Object("light");
    LightTargetsSpec spec;
    spec.light = ParseLightReference(light, lights, true, "the light's markers");
    spec.size = light.Number("size");
    RequirePositive(light, "size", spec.size);
    for (JsonObject& marker : light.Objects("markers")) {
      LightMarkerSpec m;
      m.id = marker_id(marker);
      m.light_in_marker = marker.Vector3("light_in_marker");
      if (!m.light_in_marker.allFinite()) ThrowError(marker.Where("light_in_marker"), "expected finite numbers");
      marker.Finish();
      spec.markers.push_back(m);
    }
    if (spec.markers.empty()) ThrowError(light.Where("markers"), "expected at least one marker on the light");
    light.Finish();
    targets.light = spec;
  }
  object.Finish();
  return targets;
}

CalibrationSpec ParseCalibration(JsonObject object, const std::string& directory, PhotoContext context) {
  context.white_reference = true;
  CalibrationSpec calibration;
  if (object.Has("white_reference")) {
    JsonObject white = object.Object("white_reference");
    WhiteReferenceSpec spec;
    spec.reflectance = white.Vector3("reflectance");
    if (!((spec.reflectance.array() > 0.0).all() && (spec.reflectance.array() <= 1.0).all())) {
      ThrowError(white.Where("reflectance"), "expected an albedo in (0, 1] per channel");
    }
    // Without a stated pose the card's markers (targets.white_reference) must pose it (ibrdf align).
    spec.posed = white.Has("center") || white.Has("normal") || !context.white_card;
    if (spec.posed) {
      spec.center = white.Vector3("center");
      spec.normal = white.Vector3("normal");
      if (!(spec.normal.norm() > 0.0)) ThrowError(white.Where("normal"), "must be non-zero");
      spec.normal.normalize();
    }
    spec.size = white.Number("size");
    RequirePositive(white, "size", spec.size);
    for (JsonObject& photo : white.Objects("photos")) {
      spec.photos.push_back(ParsePhoto(photo, directory, context));
      if (spec.photos.back().role != PhotoRole::kMeasurement) {
        ThrowError(photo.Where("role"), "a white-reference photo has no role");
      }
    }
    if (spec.photos.empty()) ThrowError(white.Where("photos"), "expected at least one photo of the white reference");
    white.Finish();
    calibration.white_reference = spec;
  }
  object.Finish();
  return calibration;
}

// The colour_chart block (docs/session-format.md): the chart, its photos, optional corner patches and
// the fitted matrix with its per-patch residuals.
ColourChartSpec ParseColourChart(JsonObject object, const std::string& directory, PhotoContext context) {
  context.white_reference = true;  // like a white-reference photo: no role, no mask, no pose needed
  ColourChartSpec chart;
  chart.chart = object.String("chart", kColorCheckerClassic24);
  if (chart.chart != kColorCheckerClassic24) {
    ThrowError(object.Where("chart"),
               "unknown chart \"" + chart.chart + "\" (expected \"" + std::string(kColorCheckerClassic24) + "\")");
  }
  const std::string space = object.String("space", ColourSpaceName(ColourSpace::kLinearSrgb));
  if (!ColourSpaceFromName(space, &chart.space)) {
    ThrowError(object.Where("space"), "unknown colour space \"" + space + "\" (expected linear_srgb or xyz)");
  }
  for (JsonObject& photo : object.Objects("photos")) {
    chart.photos.push_back(ParsePhoto(photo, directory, context));
    if (chart.photos.back().light != chart.photos.front().light) {
      ThrowError(photo.Where("light"), "every photo of the colour chart must be under the same light");
    }
  }
  if (chart.photos.empty()) ThrowError(object.Where("photos"), "expected at least one photo of the colour chart");
  auto matrix_rows = [&](const std::string& key, size_t rows, size_t columns, const std::string& expected) {
    const nlohmann::json& value = object.Raw(key);
    std::vector<std::vector<double>> out;
    if (!value.is_array() || value.size() != rows) ThrowError(object.Where(key), "expected " + expected);
    for (size_t r = 0; r < rows; ++r) {
      const nlohmann::json& row = value[r];
      if (!row.is_array() || row.size() != columns) ThrowError(object.Where(key), "expected " + expected);
      out.emplace_back();
      for (const nlohmann::json& v : row) {
        if (!v.is_number() || !std::isfinite(v.get<double>())) {
          ThrowError(object.Where(key) + "/" + std::to_string(r), "expected finite numbers");
        }
        out.back().push_back(v.get<double>());
      }
    }
    return out;
  };
  if (object.Has("corners")) {
    const auto rows = matrix_rows("corners", 4, 2,
                                  "4 pixel positions [[x, y] x 4]: the centres of patches 1, 6, 24 and 19 "
                                  "(top-left, top-right, bottom-right, bottom-left)");
    std::array<Eigen::Vector2d, 4> corners;
    for (int k = 0; k < 4; ++k) corners[k] = Eigen::Vector2d(rows[k][0], rows[k][1]);
    chart.corners = corners;
  }
  if (object.Has("matrix")) {
    const auto rows = matrix_rows("matrix", 3, 3, "a 3x3 matrix [[a, b, c] x 3], rows of space_from_camera");
    Eigen::Matrix3d matrix;
    for (int r = 0; r < 3; ++r) matrix.row(r) << rows[r][0], rows[r][1], rows[r][2];
    if (!(std::abs(matrix.determinant()) > 1e-12 * std::pow(matrix.cwiseAbs().maxCoeff(), 3))) {
      ThrowError(object.Where("matrix"), "the matrix is singular");
    }
    chart.matrix = matrix;
  }
  if (object.Has("patches")) {
    if (!chart.matrix) ThrowError(object.Where("patches"), "a patch fit needs its \"matrix\"");
    for (JsonObject& patch : object.Objects("patches")) {
      ColourPatchFit fit;
      fit.name = patch.String("name");
      if (patch.Has("excluded")) {
        fit.excluded = patch.String("excluded");
        if (fit.excluded.empty()) ThrowError(patch.Where("excluded"), "must say why");
      } else {
        fit.residual = patch.Number("residual");
        if (!(fit.residual >= 0.0)) ThrowError(patch.Where("residual"), "must be non-negative");
      }
      patch.Finish();
      chart.patches.push_back(fit);
    }
    if (chart.patches.size() != kColorCheckerPatches) {
      ThrowError(object.Where("patches"), "expected " + std::to_string(kColorCheckerPatches) + " patches, got " +
                                              std::to_string(chart.patches.size()));
    }
  }
  object.Finish();
  return chart;
}

nlohmann::json PoseToJson(const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", ToJson(pose.translation)}};
}

// The writers of Session::ToJson, one per block of docs/session-format.md. `named_lights` is the
// session's lights where photos and light markers name their light by id, nullptr where the session
// has one unnamed light.

nlohmann::json CornersToJson(const std::array<Eigen::Vector3d, 4>& corners) {
  nlohmann::json json = nlohmann::json::array();
  for (const Eigen::Vector3d& c : corners) json.push_back(ibrdf::ToJson(c));
  return json;
}

nlohmann::json MarkersToJson(const std::vector<TargetSpec>& markers) {
  nlohmann::json json = nlohmann::json::array();
  for (const TargetSpec& target : markers) {
    json.push_back({{"id", target.id}, {"corners", CornersToJson(target.corners)}});
  }
  return json;
}

// A mesh sample's fields: its file, pose, raw scans, scan markers and visibility.
void WriteMeshSample(const SampleSpec& sample, nlohmann::json* s) {
  (*s)["file"] = sample.mesh_file;
  if (!sample.world_from_mesh.IsIdentity()) (*s)["world_from_mesh"] = Sim3dToJson(sample.world_from_mesh);
  if (!sample.scan_inputs.empty()) {
    nlohmann::json inputs = nlohmann::json::array();
    for (const ScanInputSpec& input : sample.scan_inputs) {
      if (input.world_from_scan) {
        inputs.push_back({{"file", input.file}, {"world_from_scan", PoseToJson(*input.world_from_scan)}});
      } else {
        inputs.push_back(input.file);
      }
    }
    (*s)["scan_inputs"] = inputs;
  }
  if (!sample.scan_targets.empty()) {
    nlohmann::json targets_json = nlohmann::json::array();
    for (const ScanTargetSpec& target : sample.scan_targets) {
      targets_json.push_back({{"id", target.id}, {"corners", CornersToJson(target.corners)}});
    }
    (*s)["scan_targets"] = targets_json;
  }
  if (sample.visibility != Visibility::kAuto) (*s)["visibility"] = VisibilityName(sample.visibility);
}

// The fields a sphere and a cylinder share: centre and radius.
void WriteRoundSample(const SampleSpec& sample, nlohmann::json* s) {
  (*s)["center"] = ibrdf::ToJson(sample.center);
  (*s)["radius"] = sample.radius;
  if (sample.radius_known) (*s)["radius_known"] = true;
}

nlohmann::json SampleToJson(const SampleSpec& sample) {
  nlohmann::json s;
  s["kind"] = SampleKindName(sample.kind);
  switch (sample.kind) {
    case SampleSpec::Kind::kMesh:
      WriteMeshSample(sample, &s);
      break;
    case SampleSpec::Kind::kSphere:
      WriteRoundSample(sample, &s);
      break;
    case SampleSpec::Kind::kCylinder:
      WriteRoundSample(sample, &s);
      s["axis"] = ibrdf::ToJson(sample.axis);
      s["length"] = sample.length;
      break;
  }
  return s;
}

nlohmann::json RadiometryToJson(const RadiometrySpec& radiometry) {
  nlohmann::json r;
  switch (radiometry.response.kind) {
    case Response::Kind::kLinear:
      r["response"] = "linear";
      break;
    case Response::Kind::kSrgb:
      r["response"] = "srgb";
      break;
    case Response::Kind::kGamma:
      r["response"] = {{"gamma", radiometry.response.gamma}};
      break;
    case Response::Kind::kTable:
      r["response"] = {{"table", radiometry.response.table}};
      if (!radiometry.response.uncertainty.empty()) r["response"]["uncertainty"] = radiometry.response.uncertainty;
      break;
    case Response::Kind::kUnknown:
      r["response"] = "unknown";
      break;
  }
  r["black_level"] = radiometry.black_level;
  if (radiometry.saturation_stated) r["saturation_level"] = radiometry.saturation_level;
  if (radiometry.noise) {
    r["noise"] = {{"full_well_e", radiometry.noise->full_well_e},
                  {"read_noise_e", radiometry.noise->read_noise_e},
                  {"bits", radiometry.noise->bits}};
  }
  if (!radiometry.flat_field.empty()) r["flat_field"] = radiometry.flat_field;
  if (radiometry.relative_intensities) r["intensity_scale"] = "relative";
  return r;
}

nlohmann::json TargetsToJson(const TargetsSpec& targets, const std::vector<Light>* named_lights) {
  nlohmann::json t = {{"dictionary", targets.dictionary}, {"reference", MarkersToJson(targets.reference)}};
  if (targets.unknown_layout) {
    const UnknownLayoutSpec& layout = *targets.unknown_layout;
    t["unknown_layout"] = {{"size", layout.size}, {"ids", layout.ids}};
    if (layout.origin_id) t["unknown_layout"]["origin_id"] = *layout.origin_id;
  }
  if (targets.sample) t["sample"] = {{"markers", MarkersToJson(targets.sample->markers)}};
  if (targets.white_reference) t["white_reference"] = {{"markers", MarkersToJson(targets.white_reference->markers)}};
  if (targets.light) {
    nlohmann::json markers = nlohmann::json::array();
    for (const LightMarkerSpec& m : targets.light->markers) {
      markers.push_back({{"id", m.id}, {"light_in_marker", ibrdf::ToJson(m.light_in_marker)}});
    }
    t["light"] = {{"size", targets.light->size}, {"markers", markers}};
    if (named_lights) t["light"]["light"] = named_lights->at(targets.light->light).id;
  }
  return t;
}

nlohmann::json PhotoToJson(const PhotoSpec& photo, const std::vector<Light>* named_lights) {
  nlohmann::json p = {{"file", photo.file}, {"exposure_s", photo.exposure_s}, {"gain", photo.gain}};
  if (named_lights) p["light"] = named_lights->at(photo.light).id;
  if (!photo.mask.empty()) p["mask"] = photo.mask;
  if (photo.camera_from_world) p["camera_from_world"] = PoseToJson(*photo.camera_from_world);
  if (photo.role == PhotoRole::kTargets) p["role"] = "targets";
  if (photo.bracket) p["bracket"] = *photo.bracket;
  return p;
}

nlohmann::json CalibrationToJson(const CalibrationSpec& calibration, const std::vector<Light>* named_lights) {
  nlohmann::json json = nlohmann::json::object();
  if (calibration.white_reference) {
    const WhiteReferenceSpec& white = *calibration.white_reference;
    nlohmann::json white_photos = nlohmann::json::array();
    for (const PhotoSpec& photo : white.photos) white_photos.push_back(PhotoToJson(photo, named_lights));
    json["white_reference"] = {
        {"reflectance", ibrdf::ToJson(white.reflectance)}, {"size", white.size}, {"photos", white_photos}};
    if (white.posed) {
      json["white_reference"]["center"] = ibrdf::ToJson(white.center);
      json["white_reference"]["normal"] = ibrdf::ToJson(white.normal);
    }
  }
  return json;
}

nlohmann::json ColourChartToJson(const ColourChartSpec& chart, const std::vector<Light>* named_lights) {
  nlohmann::json c = {
      {"chart", chart.chart}, {"space", ColourSpaceName(chart.space)}, {"photos", nlohmann::json::array()}};
  for (const PhotoSpec& photo : chart.photos) c["photos"].push_back(PhotoToJson(photo, named_lights));
  if (chart.corners) {
    for (const Eigen::Vector2d& p : *chart.corners) c["corners"].push_back({p.x(), p.y()});
  }
  if (chart.matrix) {
    for (int row = 0; row < 3; ++row)
      c["matrix"].push_back({(*chart.matrix)(row, 0), (*chart.matrix)(row, 1), (*chart.matrix)(row, 2)});
  }
  for (const ColourPatchFit& fit : chart.patches) {
    c["patches"].push_back(fit.excluded.empty() ? nlohmann::json{{"name", fit.name}, {"residual", fit.residual}}
                                                : nlohmann::json{{"name", fit.name}, {"excluded", fit.excluded}});
  }
  return c;
}

}  // namespace

const char* SampleKindName(SampleSpec::Kind kind) {
  switch (kind) {
    case SampleSpec::Kind::kSphere:
      return "sphere";
    case SampleSpec::Kind::kCylinder:
      return "cylinder";
    case SampleSpec::Kind::kMesh:
      return "mesh";
  }
  UnhandledKind("SampleSpec::Kind", static_cast<int>(kind));
}

bool IsMeshSample(SampleSpec::Kind kind) {
  switch (kind) {
    case SampleSpec::Kind::kSphere:
    case SampleSpec::Kind::kCylinder:
      return false;
    case SampleSpec::Kind::kMesh:
      return true;
  }
  UnhandledKind("SampleSpec::Kind", static_cast<int>(kind));
}

const char* VisibilityName(Visibility visibility) {
  switch (visibility) {
    case Visibility::kAuto:
      return "auto";
    case Visibility::kOn:
      return "on";
    case Visibility::kOff:
      return "off";
  }
  UnhandledKind("Visibility", static_cast<int>(visibility));
}

bool VisibilityFromName(const std::string& name, Visibility* visibility) {
  for (Visibility v : {Visibility::kAuto, Visibility::kOn, Visibility::kOff}) {
    if (name == VisibilityName(v)) {
      *visibility = v;
      return true;
    }
  }
  return false;
}

const char* SessionStageName(SessionStage stage) {
  switch (stage) {
    case SessionStage::kScan:
      return "scan";
    case SessionStage::kAlign:
      return "align";
    case SessionStage::kLights:
      return "lights";
    case SessionStage::kColour:
      return "colour";
    case SessionStage::kResponse:
      return "response";
  }
  UnhandledKind("SessionStage", static_cast<int>(stage));
}

bool SessionStageFromName(const std::string& name, SessionStage* stage) {
  for (SessionStage candidate : {SessionStage::kScan, SessionStage::kAlign, SessionStage::kLights, SessionStage::kColour,
                                 SessionStage::kResponse}) {
    if (name == SessionStageName(candidate)) {
      *stage = candidate;
      return true;
    }
  }
  return false;
}

bool Session::Applied(SessionStage stage) const {
  return std::find(stages_applied.begin(), stages_applied.end(), stage) != stages_applied.end();
}

void Session::MarkApplied(SessionStage stage) {
  if (!Applied(stage)) stages_applied.push_back(stage);
}

Session Session::Load(const std::string& path) {
  Session session;
  session.manifest_path = fs::is_directory(path) ? (fs::path(path) / "session.json").string() : path;
  RequireFile(session.manifest_path, "session manifest");
  session.directory = fs::path(session.manifest_path).parent_path().string();
  if (session.directory.empty()) session.directory = ".";
  const nlohmann::json json = ReadJsonFile(session.manifest_path);
  JsonObject root(json, session.manifest_path);
  const std::string format = root.String("format");
  if (format != kFormat) ThrowError(root.Where("format"), "expected \"" + std::string(kFormat) + "\"");
  const int version = root.Integer("version");
  if (version != 1 && version != 2) {
    ThrowError(root.Where("version"),
               "unsupported version " + std::to_string(version) + " (this ibrdf reads versions 1 and 2)");
  }
  session.name = root.String("name", fs::path(session.directory).filename().string());
  session.description = root.String("description", "");
  session.camera = ParseCamera(root.Object("camera"));
  session.lights.clear();
  if (version >= 2 && root.Has("lights")) {
    if (root.Has("light")) {
      ThrowError(root.Where("light"), "give either one \"light\" or a \"lights\" array, not both");
    }
    for (JsonObject& light : root.Objects("lights")) {
      session.lights.push_back(ParseLight(light, version, true));
      for (size_t k = 0; k + 1 < session.lights.size(); ++k) {
        if (session.lights[k].id == session.lights.back().id) {
          ThrowError(light.Where("id"), "light id \"" + session.lights.back().id + "\" is listed twice");
        }
      }
    }
    if (session.lights.empty()) ThrowError(root.Where("lights"), "expected at least one light");
  } else {
    session.lights.push_back(ParseLight(root.Object("light"), version, false));
  }
  if (version >= 2 && root.Has("mask")) {
    session.mask = root.String("mask");
    if (session.mask.empty()) ThrowError(root.Where("mask"), "empty file name");
    const std::string mask_path = ResolvePath(session.directory, session.mask);
    if (!fs::is_regular_file(mask_path)) ThrowError(root.Where("mask"), "mask " + mask_path + " does not exist");
  }
  PhotoContext context;
  context.version = version;
  context.lights = &session.lights;
  session.sample = ParseSample(root.Object("sample"));
  if (root.Has("radiometry")) session.radiometry = ParseRadiometry(root.Object("radiometry"), session.directory);
  if (root.Has("targets")) session.targets = ParseTargets(root.Object("targets"), session.lights);
  if (root.Has("calibration")) {
    context.white_card = session.targets && session.targets->white_reference;
    session.calibration = ParseCalibration(root.Object("calibration"), session.directory, context);
  }
  if (root.Has("colour_chart")) {
    session.colour_chart = ParseColourChart(root.Object("colour_chart"), session.directory, context);
  }
  if (root.Has("stages_applied")) {
    const nlohmann::json& stages = root.Raw("stages_applied");
    if (!stages.is_array()) ThrowError(root.Where("stages_applied"), "expected an array of stage names");
    for (size_t i = 0; i < stages.size(); ++i) {
      const std::string where = root.Where("stages_applied") + "/" + std::to_string(i);
      SessionStage stage;
      if (!stages[i].is_string() || !SessionStageFromName(stages[i].get<std::string>(), &stage)) {
        ThrowError(where, "expected \"scan\", \"align\", \"lights\", \"colour\" or \"response\", got " + stages[i].dump());
      }
      if (session.Applied(stage)) ThrowError(where, "\"" + std::string(SessionStageName(stage)) + "\" is listed twice");
      session.stages_applied.push_back(stage);
    }
  }
  for (JsonObject& photo : root.Objects("photos")) {
    session.photos.push_back(ParsePhoto(photo, session.directory, context));
  }
  if (session.photos.empty()) ThrowError(root.Where("photos"), "a session needs at least one photo");
  // A light of unknown position needs the markers that let align find it.
  for (size_t k = 0; k < session.lights.size(); ++k) {
    if (session.lights[k].placement_known) continue;
    if (!session.targets || !session.targets->light || session.targets->light->light != k) {
      const std::string pointer = root.Has("lights") ? "/lights/" + std::to_string(k) : "/light";
      ThrowError(session.manifest_path + ": " + pointer + "/position",
                 LightLabel(session.lights[k]) +
                     "'s position is \"unknown\", but no light markers (targets.light) let `ibrdf align` find it: "
                     "give the position in metres");
    }
  }
  // A light without a stated intensity needs a calibration that measures it.
  for (size_t k = 0; k < session.lights.size(); ++k) {
    const Light& light = session.lights[k];
    if (light.has_intensity) continue;
    bool calibrated = false;
    if (session.calibration && session.calibration->white_reference) {
      for (const PhotoSpec& photo : session.calibration->white_reference->photos) calibrated |= photo.light == k;
    }
    if (!calibrated) {
      const std::string pointer = root.Has("lights") ? "/lights/" + std::to_string(k) : "/light";
      ThrowError(session.manifest_path + ": " + pointer,
                 LightLabel(light) +
                     " has no intensity and no calibration measures it: give its \"intensity\", or "
                     "white-reference photos under it (calibration.white_reference.photos" +
                     (light.id.empty() ? std::string() : " with \"light\": \"" + light.id + "\"") + ")");
    }
  }
  root.Finish();
  return session;
}

nlohmann::json Session::ToJson() const {
  nlohmann::json json;
  json["format"] = kFormat;
  json["version"] = kVersion;
  json["name"] = name;
  if (!description.empty()) json["description"] = description;
  json["camera"] = {{"model", CameraModelName(camera.model)},
                    {"width", camera.width},
                    {"height", camera.height},
                    {"params", camera.params}};
  IBRDF_CHECK(!lights.empty()) << "a session without lights";
  // One unnamed light: the `light` shorthand; otherwise the `lights` array, and photos name theirs.
  const bool named_lights = lights.size() > 1 || !lights[0].id.empty();
  if (!named_lights) {
    json["light"] = LightJson(lights[0]);
  } else {
    json["lights"] = nlohmann::json::array();
    for (const Light& light : lights) json["lights"].push_back(LightJson(light));
  }
  if (!mask.empty()) json["mask"] = mask;
  json["sample"] = SampleToJson(sample);
  json["radiometry"] = RadiometryToJson(radiometry);
  const std::vector<Light>* named = named_lights ? &lights : nullptr;
  if (targets) json["targets"] = TargetsToJson(*targets, named);
  if (calibration) json["calibration"] = CalibrationToJson(*calibration, named);
  if (colour_chart) json["colour_chart"] = ColourChartToJson(*colour_chart, named);
  if (!stages_applied.empty()) {
    json["stages_applied"] = nlohmann::json::array();
    for (SessionStage stage : stages_applied) json["stages_applied"].push_back(SessionStageName(stage));
  }
  json["photos"] = nlohmann::json::array();
  for (const PhotoSpec& photo : photos) json["photos"].push_back(PhotoToJson(photo, named));
  return json;
}

void Session::Save(const std::string& path) const { WriteJsonFile(path, ToJson()); }

std::string Session::AbsolutePath(const std::string& file) const {
  return fs::absolute(ResolvePath(directory, file)).lexically_normal().string();
}

Session Session::Rebased(const std::string& dir, PathStyle style) const {
  const fs::path folder = fs::absolute(dir).lexically_normal();
  auto rebase = [&](std::string* file) {
    if (file->empty()) return;
    const fs::path absolute = AbsolutePath(*file);
    const fs::path relative = absolute.lexically_relative(folder);
    *file = style == PathStyle::kAbsolute || relative.empty() ? absolute.string() : relative.string();
  };
  Session rebased = *this;
  for (PhotoSpec& photo : rebased.photos) {
    rebase(&photo.file);
    rebase(&photo.mask);
  }
  rebase(&rebased.mask);
  rebase(&rebased.radiometry.flat_field);
  if (rebased.calibration && rebased.calibration->white_reference) {
    for (PhotoSpec& photo : rebased.calibration->white_reference->photos) rebase(&photo.file);
  }
  if (rebased.colour_chart) {
    for (PhotoSpec& photo : rebased.colour_chart->photos) rebase(&photo.file);
  }
  if (IsMeshSample(rebased.sample.kind)) {
    rebase(&rebased.sample.mesh_file);
    for (ScanInputSpec& input : rebased.sample.scan_inputs) rebase(&input.file);
  }
  rebased.directory = folder.string();
  rebased.manifest_path = (folder / "session.json").string();
  return rebased;
}

std::string Session::SaveRebased(const std::string& dir, PathStyle style) const {
  const Session rebased = Rebased(dir, style);
  rebased.Save(rebased.manifest_path);
  return rebased.manifest_path;
}

std::vector<std::string> Session::InputFiles() const {
  std::vector<std::string> files;
  for (const PhotoSpec& photo : photos) files.push_back(AbsolutePath(photo.file));
  if (!mask.empty()) files.push_back(AbsolutePath(mask));
  for (const PhotoSpec& photo : photos) {
    if (!photo.mask.empty()) files.push_back(AbsolutePath(photo.mask));
  }
  if (!radiometry.flat_field.empty()) files.push_back(AbsolutePath(radiometry.flat_field));
  if (calibration && calibration->white_reference) {
    for (const PhotoSpec& photo : calibration->white_reference->photos) files.push_back(AbsolutePath(photo.file));
  }
  if (colour_chart) {
    for (const PhotoSpec& photo : colour_chart->photos) files.push_back(AbsolutePath(photo.file));
  }
  if (IsMeshSample(sample.kind)) {
    files.push_back(AbsolutePath(sample.mesh_file));
    for (const ScanInputSpec& input : sample.scan_inputs) files.push_back(AbsolutePath(input.file));
  }
  return files;
}

std::string Session::PhotoPath(size_t i) const { return ResolvePath(directory, photos.at(i).file); }

const Light& Session::PhotoLight(size_t i) const {
  const size_t light = photos.at(i).light;
  IBRDF_CHECK(light < lights.size()) << "photo " << i << " names light " << light << " of " << lights.size();
  return lights[light];
}

std::string Session::PhotoMaskPath(size_t i) const {
  const PhotoSpec& photo = photos.at(i);
  if (photo.role == PhotoRole::kTargets) return "";
  const std::string& file = photo.mask.empty() ? mask : photo.mask;
  return file.empty() ? "" : ResolvePath(directory, file);
}

int Session::LightIndex(const std::string& id) const {
  for (size_t k = 0; k < lights.size(); ++k) {
    if (lights[k].id == id) return static_cast<int>(k);
  }
  return -1;
}

void Session::CheckPhotos() const {
  for (size_t i = 0; i < photos.size(); ++i) {
    const ImageSpec spec = ReadImageSpec(PhotoPath(i));
    if (spec.width != camera.width || spec.height != camera.height) {
      ThrowError(PhotoPath(i), "photo is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                   " but the session's camera is " + std::to_string(camera.width) + "x" +
                                   std::to_string(camera.height) + " (" + manifest_path + ": /photos/" +
                                   std::to_string(i) + ")");
    }
    if (spec.channels != 1 && spec.channels < 3) {
      ThrowError(PhotoPath(i), "expected 1 (grey) or 3+ (RGB) channels, got " + std::to_string(spec.channels));
    }
    const std::string mask_path = PhotoMaskPath(i);
    if (!mask_path.empty()) {
      const ImageSpec mask_spec = ReadImageSpec(mask_path);
      if (mask_spec.width != spec.width || mask_spec.height != spec.height) {
        ThrowError(mask_path, "mask is " + std::to_string(mask_spec.width) + "x" + std::to_string(mask_spec.height) +
                                  " but its photo " + PhotoPath(i) + " is " + std::to_string(spec.width) + "x" +
                                  std::to_string(spec.height) + " (" + manifest_path + ": /photos/" +
                                  std::to_string(i) + ")");
      }
    }
  }
}

}  // namespace ibrdf
