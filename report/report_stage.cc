#include "report/report_stage.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/brdf_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/linear_image.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/truth_comparison.h"
#include "report/light_photos.h"
#include "report/photo_statistics.h"
#include "report/report_script.h"
#include "report/sphere_render.h"
#include "report/tone_map.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// The reconstruction and the truth, when the run has them.
struct RunModels {
  std::unique_ptr<MerlTable> table;
  std::unique_ptr<BrdfModel> truth;
  std::string truth_path;
};

RunModels LoadRunModels(const fs::path& run_dir) {
  RunModels models;
  const std::string merl_path = (run_dir / "reconstruction" / "brdf.binary").string();
  if (fs::exists(merl_path)) models.table = std::make_unique<MerlTable>(ReadMerl(merl_path));
  const fs::path comparison = run_dir / "truth-comparison.json";
  if (fs::exists(comparison)) {
    const nlohmann::json json = ReadJsonFile(comparison.string());
    if (json.contains("truth") && json["truth"].is_string() && fs::exists(json["truth"].get<std::string>())) {
      models.truth_path = json["truth"].get<std::string>();
      models.truth = LoadTruthMaterial(models.truth_path);
    }
  }
  return models;
}

// The measured photo, cropped to the samples' pixel box, linearized and tone-mapped into photo.png.
// Errors reading the samples' session become a note in the data instead of failing the report.
void WritePhoto(const std::string& samples_path, const PhotoStats& p, const ChosenPhoto& chosen, const fs::path& tmp,
                nlohmann::json* data, ReportResult* result) {
  const fs::path sidecar(SidecarPath(samples_path));
  if (!fs::exists(sidecar)) return;
  const nlohmann::json side = ReadJsonFile(sidecar.string());
  try {
    const Session session = Session::Load(side.at("session").get<std::string>());
    if (chosen.photo >= session.photos.size())
      ThrowError(session.manifest_path, "has fewer photos than the samples name");
    const int pad = std::max(4, (p.x1 - p.x0) / 8);
    Image photo = ReadImage(session.PhotoPath(chosen.photo));
    LinearizeImage(session, chosen.photo, &photo, /*divide_by_exposure=*/true);
    const int x0 = std::max(0, p.x0 - pad), y0 = std::max(0, p.y0 - pad);
    const int x1 = std::min(photo.width - 1, p.x1 + pad), y1 = std::min(photo.height - 1, p.y1 + pad);
    Image crop(x1 - x0 + 1, y1 - y0 + 1, 3);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        for (int c = 0; c < 3; ++c) crop.at(x - x0, y - y0, c) = photo.at(x, y, std::min(c, photo.channels - 1));
      }
    }
    WriteImage((tmp / "photo.png").string(), ToneMap(crop, nullptr), PixelFormat::kUint8);
    (*data)["photo"] = {
        {"file", "photo.png"},      {"source", session.PhotoPath(chosen.photo)}, {"index", chosen.photo},
        {"crop", {x0, y0, x1, y1}}, {"phase_deg", chosen.phase / kDeg},          {"samples", p.count}};
    result->photo_shown = true;
  } catch (const Error& e) {
    result->photo_note = e.what();
    Log(1, "report: no photo: " + result->photo_note);
  }
  if (!result->photo_note.empty()) (*data)["photo_note"] = result->photo_note;
}

// Spheres of the reconstructed (and the true) material, lit at the chosen photo's phase angle.
void WriteRenders(const RunModels& models, int size, double phase, const fs::path& tmp, nlohmann::json* data) {
  if (models.table) {
    const Image render = RenderSphere(size, phase, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
      return models.table->Lookup(wi, wo);
    });
    WriteImage((tmp / "render.png").string(), ToneMap(render, nullptr), PixelFormat::kUint8);
    (*data)["render"] = {{"file", "render.png"}, {"phase_deg", phase / kDeg}};
  }
  if (models.truth) {
    const Image render = RenderSphere(
        size, phase, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return models.truth->Eval(wi, wo); });
    WriteImage((tmp / "render-truth.png").string(), ToneMap(render, nullptr), PixelFormat::kUint8);
    (*data)["render_truth"] = {{"file", "render-truth.png"}, {"phase_deg", phase / kDeg}};
    (*data)["truth"] = models.truth_path;
  }
}

// The reconstruction and the truth along the incidence plane: theta_0 fixed, the other angle signed
// (positive on the light's side, delta_phi = 0; negative on the mirror side, delta_phi = pi).
nlohmann::json IncidencePlaneCurves(const RunModels& models) {
  nlohmann::json curves = nlohmann::json::array();
  for (const double theta0 : {15.0, 30.0, 45.0, 60.0}) {
    nlohmann::json angles = nlohmann::json::array(), recon = nlohmann::json::array(),
                   true_values = nlohmann::json::array();
    for (double x = -88.0; x <= 88.0; x += 0.5) {
      const Eigen::Vector3d wi(std::sin(theta0 * kDeg), 0.0, std::cos(theta0 * kDeg));
      const Eigen::Vector3d wo(std::sin(x * kDeg), 0.0, std::cos(x * kDeg));
      angles.push_back(x);
      if (models.table) {
        const Eigen::Vector3d f = models.table->Lookup(wi, wo);
        recon.push_back({f[0], f[1], f[2]});
      }
      if (models.truth) {
        const Eigen::Vector3d f = models.truth->Eval(wi, wo);
        true_values.push_back({f[0], f[1], f[2]});
      }
    }
    curves.push_back(
        {{"theta0_deg", theta0}, {"angle_deg", angles}, {"reconstruction", recon}, {"truth", true_values}});
  }
  return curves;
}

}  // namespace

bool ReportOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(render_size, 16, 4096);
  return true;
}

std::string ReportResult::BriefReport() const {
  std::ostringstream out;
  out << "report: " << (success ? index_html : "FAILED") << ", " << samples << " samples, photo " << photo << " ("
      << phase_deg << " deg phase" << (photo_shown ? ", shown" : ", not shown") << ")"
      << (reconstruction ? ", reconstruction" : "") << (truth ? ", truth" : "");
  return out.str();
}

ReportResult WriteReport(const std::string& run_dir_name, const ReportOptions& options, const std::string& out_dir) {
  std::string why;
  if (!options.Check(&why)) ThrowError("report options", why);
  const fs::path run_dir(run_dir_name);
  if (!fs::is_directory(run_dir))
    ThrowError(run_dir_name, "is not a folder (expected the output folder of `ibrdf run`)");
  const std::string samples_path = (run_dir / "samples.npy").string();
  if (!fs::is_regular_file(samples_path))
    ThrowError(samples_path, "does not exist: not the folder of a completed `ibrdf run` (it has no samples)");
  const std::string out = out_dir.empty() ? (run_dir / "report").string() : out_dir;
  const std::string script = options.script.empty() ? FindReportScript() : options.script;
  const std::string python = options.python.empty() ? ReportPython() : options.python;
  RequireFile(script, "the report's plotting script (IBRDF_REPORT_SCRIPT)");
  RequireFile(python, "python3 with matplotlib (Debian: python3-matplotlib)");

  const std::vector<BrdfSample> samples = ReadSamples(samples_path);
  if (samples.empty()) ThrowError(samples_path, "holds no samples");
  ReportResult result;
  result.samples = samples.size();
  nlohmann::json data = {{"format", "ibrdf-report-data"}, {"version", 1}};
  // The photo: the one whose median angle between light and view is the median over photos.
  std::map<uint32_t, PhotoStats> photos = CollectPhotoStats(samples);
  const ChosenPhoto chosen = ChoosePhoto(photos, options.photo);
  result.photo = chosen.photo;
  result.phase_deg = chosen.phase / kDeg;
  const RunModels models = LoadRunModels(run_dir);
  result.reconstruction = models.table != nullptr;
  result.truth = models.truth != nullptr;

  AtomicDirectory directory(out, options.overwrite);
  const fs::path tmp(directory.temporary_path());
  WritePhoto(samples_path, photos[chosen.photo], chosen, tmp, &data, &result);
  // Multi-light sessions (a dome, a turntable): the lights and a photo under each.
  const nlohmann::json lights = WriteLightPhotos(samples_path, photos, tmp.string());
  if (!lights.is_null()) data["lights"] = lights;
  WriteRenders(models, options.render_size, chosen.phase, tmp, &data);
  data["incidence_plane"] = IncidencePlaneCurves(models);
  WriteJsonFile((tmp / "report-data.json").string(), data);
  RunReportScript(python, script, run_dir.string(), tmp.string());
  directory.Commit();
  result.index_html = (fs::path(out) / "index.html").string();
  Log(1, "report written to " + result.index_html);
  result.success = true;
  return result;
}

}  // namespace ibrdf
