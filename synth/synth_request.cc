#include "synth/synth_request.h"

#include <filesystem>
#include <vector>

#include "core/colour.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/merl_brdf.h"
#include "core/output_guard.h"
#include "core/session.h"
#include "synth/material_map.h"
#include "synth/synthetic.h"

namespace ibrdf {

namespace fs = std::filesystem;

SynthOptions SynthOptionsFromRequest(const SynthRequest& request) {
  SynthOptions options = request.options;
  options.scene.sample = request.sample == "cylinder" ? SampleSpec::Kind::kCylinder : SampleSpec::Kind::kSphere;
  options.rig.rig = SynthRigFromName(request.rig);
  options.effects = request.effects == "none" ? CameraEffects::None() : CameraEffects();
  CameraEffects& e = options.effects;
  if (request.bits >= 0) e.bits = request.bits;
  if (request.supersample >= 0) e.supersample = request.supersample;
  if (request.black_level >= 0) e.black_level = request.black_level;
  if (request.full_well_e >= 0) e.full_well_e = request.full_well_e;
  if (request.read_noise_e >= 0) e.read_noise_e = request.read_noise_e;
  if (request.vignetting >= 0) e.vignetting = request.vignetting;
  if (request.srgb) e.curve = SensorCurve::kSrgb;
  if (!request.response.empty()) {
    if (!SensorCurveFromName(request.response, &e.curve)) {
      ThrowError("--response", "unknown curve \"" + request.response + "\" (expected linear, srgb or toe-shoulder)");
    }
    if (request.srgb && e.curve != SensorCurve::kSrgb) ThrowError("--response", "contradicts --srgb");
  }
  if (request.no_shot_noise) e.shot_noise = false;
  if (request.no_read_noise) e.read_noise = false;
  if (request.no_clip) {
    if (e.bits != 0) ThrowError("--no-clip", "unclipped values need float output (--bits 0)");
    e.clip = false;
  }
  bool targets = request.targets;
  if (!request.shape.empty()) {
    options.scene.shape = SynthShapeFromName(request.shape);
    targets = true;
  }
  if (targets) {
    options.targets.enabled = true;
    if (!request.camera_elevation_given) options.rig.camera_elevation_deg = 45.0;
    if (!request.light_photos_given) options.targets.light_photos = 3;
  }
  const std::vector<double>& o = request.origin;
  if (!o.empty() && o.size() != 3) ThrowError("--origin-m", "expected 3 values (x y z)");
  if (!o.empty()) options.scene.origin = Eigen::Vector3d(o[0], o[1], o[2]);
  const std::vector<double>& i = request.light_intensity;
  if (!i.empty() && i.size() != 3) ThrowError("--light-intensity", "expected 3 values (R G B)");
  if (!i.empty()) options.scene.light_intensity = Eigen::Vector3d(i[0], i[1], i[2]);
  const std::vector<double>& m = request.camera_matrix;
  if (!m.empty() && m.size() != 9) ThrowError("--camera-matrix", "expected 9 values (row by row)");
  if (!m.empty()) {
    options.colour.camera_matrix = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
  }
  options.colour.chart_corners = !request.colour_chart_detect;
  if (!ColourSpaceFromName(request.colour_space, &options.colour.space)) {
    ThrowError("--colour-space", "unknown space \"" + request.colour_space + "\" (expected linear_srgb or xyz)");
  }
  options.no_data = SynthNoDataFromName(request.no_data);
  return options;
}

std::unique_ptr<BrdfModel> LoadRequestedMaterial(const SynthRequest& request, const std::string& path) {
  std::unique_ptr<BrdfModel> material = LoadMaterial(path);
  if (!request.merl_lookup_given) return material;
  const auto* table = dynamic_cast<const MerlBrdf*>(material.get());
  if (!table) ThrowError(path, "--merl-lookup applies to MERL tables (.binary) only");
  return std::make_unique<MerlBrdf>(table->table(), table->path(),
                                    MerlLookupFromName(request.merl_lookup, "synth --merl-lookup"));
}

CharucoPhotosSummary WriteSessionCharucoPhotos(const std::string& session_dir, int num_photos, uint64_t session_seed) {
  CharucoPhotoOptions board;
  board.num_photos = num_photos;
  board.seed = session_seed + 1000;
  const Camera camera = Session::Load(session_dir).camera;
  const fs::path calibration = fs::path(session_dir) / "calibration";
  if (!fs::exists(calibration)) return WriteCharucoPhotos(camera, board, calibration.string(), /*overwrite=*/false);
  // The session's own calibration photos (colour chart, white reference) are there already: the board's
  // files are written whole beside them, then join them; none of their names is one of the session's.
  const fs::path staging = fs::path(session_dir) / ".calibration-charuco";
  const CharucoPhotosSummary summary = WriteCharucoPhotos(camera, board, staging.string(), /*overwrite=*/true);
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(staging)) files.push_back(entry.path());
  for (const fs::path& file : files) {
    if (fs::exists(calibration / file.filename())) {
      fs::remove_all(staging);
      ThrowError((calibration / file.filename()).string(), "exists: the ChArUco photos' file would replace it");
    }
  }
  for (const fs::path& file : files) fs::rename(file, calibration / file.filename());
  fs::remove(staging);
  return summary;
}

namespace {
// A material map file and the material files it names (for the output guard), once it loaded.
std::vector<std::string> MapInputFiles(const std::string& map_path) {
  std::vector<std::string> files = {map_path};
  const nlohmann::json json = ReadJsonFile(map_path);
  for (const nlohmann::json& entry : json.at("materials")) {
    if (entry.is_string()) files.push_back((fs::path(map_path).parent_path() / entry.get<std::string>()).string());
  }
  return files;
}
}  // namespace

void WriteSynthStage(const SynthRequest& request, const SynthOptions& options, const std::string& material_path,
                     const std::string& out, bool overwrite) {
  const std::string& map_path = request.material_map;
  if (material_path.empty() == map_path.empty()) {
    ThrowError("--material, --material-map",
               material_path.empty() ? "give one: a material, or a material map (a spatially varying sample)"
                                     : "give one, not both: a material map replaces the material");
  }
  if (!map_path.empty()) {
    if (request.merl_lookup_given) {
      ThrowError("--merl-lookup", "applies to --material's MERL table, not to a material map's materials");
    }
    const MaterialMap map = MaterialMap::Load(map_path);
    RequireWritableOutput(out, overwrite, MapInputFiles(map_path));
    const SynthSummary summary = WriteSyntheticSession(options, map, map_path, out, overwrite);
    Log(1, summary.BriefReport() + ", " + std::to_string(map.NumMaterials()) + " materials in a material map");
    Log(1, "session written to " + out + "/session.json (truth, the material map, in " + out + "/truth.json)");
  } else {
    RequireWritableOutput(out, overwrite, {material_path});
    const std::unique_ptr<BrdfModel> material = LoadRequestedMaterial(request, material_path);
    const SynthSummary summary = WriteSyntheticSession(options, *material, material_path, out, overwrite);
    Log(1, summary.BriefReport());
    if (!summary.NoDataReport().empty()) {
      const bool invented = summary.no_data == SynthNoData::kZero;  // zero-valued samples: a warning
      Log(invented ? 0 : 1, std::string(invented ? "warning: " : "") + material_path + ": " + summary.NoDataReport() +
                                " (truth.json generator.material_no_data)");
    }
    Log(1, "session written to " + out + "/session.json (truth in " + out + "/truth.json)");
  }
  if (request.charuco_photos > 0) {
    const CharucoPhotosSummary photos = WriteSessionCharucoPhotos(out, request.charuco_photos, options.seed);
    Log(1, photos.BriefReport() + ", written to " + out + "/calibration");
  }
}

}  // namespace ibrdf
