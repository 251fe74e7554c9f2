// ibrdf report: the consistency report of a run folder, one self-contained HTML file with PNG figures
// beside it, like the paper's summary figures. This command does what needs the session and the BRDF
// models (the measured photo, rendered spheres, reconstruction and truth along the incidence plane);
// scripts/report.py (matplotlib) draws the plots and writes the HTML. docs/report.md describes it.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/statistics.h"
#include "core/subprocess.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/linear_image.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/radiometry.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/truth_comparison.h"

#ifndef IBRDF_REPORT_SCRIPT
#define IBRDF_REPORT_SCRIPT "scripts/report.py"
#endif
#ifndef IBRDF_PYTHON
#define IBRDF_PYTHON "/usr/bin/python3"
#endif

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

struct ReportOptions {
  int photo = -1;         // the measured photo shown beside the renders (-1: the median phase angle)
  int render_size = 256;  // pixels, square renders of a sphere
  bool Check(std::string* why) const {
    if (render_size < 16 || render_size > 4096) {
      *why = "--render-size must be in [16, 4096]";
      return false;
    }
    return true;
  }
};

// Per photo: how many samples, the pixel box they cover, and the median angle between wi and wo.
struct PhotoStats {
  size_t count = 0;
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  std::vector<float> phase;
};

// Linear RGB (NaN marks "no value") to an 8-bit-ready sRGB image, scaled so that the 99th percentile
// of the luminance lands at 0.8; NaN pixels are drawn magenta.
Image ToneMap(const Image& linear, double* scale_out) {
  std::vector<double> luminance;
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      const double l = 0.2126 * linear.at(x, y, 0) + 0.7152 * linear.at(x, y, 1) + 0.0722 * linear.at(x, y, 2);
      if (std::isfinite(l) && l > 0.0) luminance.push_back(l);
    }
  }
  const double p99 = Percentile(luminance, 0.99);
  const double scale = p99 > 0.0 ? 0.8 / p99 : 1.0;
  if (scale_out) *scale_out = scale;
  Image out(linear.width, linear.height, 3);
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = linear.at(x, y, c);
        out.at(x, y, c) =
            std::isfinite(v) ? float(LinearToSrgb(std::clamp(v * scale, 0.0, 1.0))) : (c == 1 ? 0.0f : 1.0f);
      }
    }
  }
  return out;
}

// A sphere seen orthographically from +z (y up), lit by a distant light at `phase` radians from the
// view direction in the horizontal plane, unit irradiance at normal incidence: radiance f cos(theta_i).
template <typename Eval>
Image RenderSphere(int size, double phase, const Eval& eval) {
  Image image(size, size, 3);
  const Eigen::Vector3d view(0, 0, 1), light(-std::sin(phase), 0.0, std::cos(phase));  // light from the left
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double u = 2.0 * (x + 0.5) / size - 1.0, v = 1.0 - 2.0 * (y + 0.5) / size;
      const double r2 = u * u + v * v;
      if (r2 >= 1.0) continue;  // background stays black
      const Eigen::Vector3d n(u, v, std::sqrt(1.0 - r2));
      const double cos_i = n.dot(light);
      if (cos_i <= 0.0) continue;
      const Eigen::Matrix3d local_from_world =
          Eigen::Quaterniond::FromTwoVectors(n, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const Eigen::Vector3d f = eval(local_from_world * light, local_from_world * view);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = f[c] < 0.0 ? NAN : float(f[c] * cos_i);
    }
  }
  return image;
}

void AddReportCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "report",
      "The consistency report of an `ibrdf run` folder: OUT/index.html (self-contained, figures embedded)\n"
      "and the PNG figures beside it: sample coverage, incidence-plane plots per channel with the\n"
      "reconstruction, reciprocity and bilateral symmetry, a rendered sphere beside a measured photo,\n"
      "timings and rejected samples. Plots by matplotlib (scripts/report.py, Debian's python3).");
  struct Args {
    std::string run_dir, out;
    ReportOptions options;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command
      ->add_option("run_dir", args->run_dir,
                   "Run folder of `ibrdf run` (samples.npy, consistency.json, reconstruction/ ...)")
      ->required();
  command->add_option("--out", args->out, "Report folder to write (default: RUN_DIR/report)");
  command->add_option("--photo", args->options.photo,
                      "Photo index shown beside the render (default: median phase angle)");
  command->add_option("--render-size", args->options.render_size, "Rendered sphere size, pixels")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing report folder");
  command->callback([args] {
    StageLog stage("report");
    std::string why;
    if (!args->options.Check(&why)) ThrowError("ibrdf report", why);
    const fs::path run_dir(args->run_dir);
    if (!fs::is_directory(run_dir))
      ThrowError(args->run_dir, "is not a folder (expected the output folder of `ibrdf run`)");
    const std::string samples_path = (run_dir / "samples.npy").string();
    if (!fs::is_regular_file(samples_path))
      ThrowError(samples_path, "does not exist: not the folder of a completed `ibrdf run` (it has no samples)");
    const std::string out = args->out.empty() ? (run_dir / "report").string() : args->out;
    const char* script_env = std::getenv("IBRDF_REPORT_SCRIPT");
    const std::string script = script_env ? script_env : IBRDF_REPORT_SCRIPT;
    RequireFile(script, "the report's plotting script (IBRDF_REPORT_SCRIPT)");
    RequireFile(IBRDF_PYTHON, "python3 with matplotlib (Debian: python3-matplotlib)");

    const std::vector<BrdfSample> samples = ReadSamples(samples_path);
    if (samples.empty()) ThrowError(samples_path, "holds no samples");
    nlohmann::json data = {{"format", "ibrdf-report-data"}, {"version", 1}};

    // The photo: the one whose median angle between light and view is the median over photos.
    std::map<uint32_t, PhotoStats> photos;
    for (const BrdfSample& s : samples) {
      PhotoStats& p = photos[s.image];
      ++p.count;
      p.x0 = std::min<int>(p.x0, s.pixel[0]);
      p.y0 = std::min<int>(p.y0, s.pixel[1]);
      p.x1 = std::max<int>(p.x1, s.pixel[0]);
      p.y1 = std::max<int>(p.y1, s.pixel[1]);
      const double c = s.wi[0] * s.wo[0] + s.wi[1] * s.wo[1] + s.wi[2] * s.wo[2];
      if (p.phase.size() < 4096 || (p.count % 64) == 0) p.phase.push_back(float(std::acos(std::clamp(c, -1.0, 1.0))));
    }
    std::vector<std::pair<double, uint32_t>> by_phase;
    for (auto& [image, p] : photos) {
      std::vector<double> phase(p.phase.begin(), p.phase.end());
      by_phase.emplace_back(Percentile(phase, 0.5), image);
    }
    std::sort(by_phase.begin(), by_phase.end());
    uint32_t chosen = by_phase[by_phase.size() / 2].second;
    double phase = by_phase[by_phase.size() / 2].first;
    if (args->options.photo >= 0) {
      const auto found = std::find_if(by_phase.begin(), by_phase.end(),
                                      [&](const auto& e) { return e.second == uint32_t(args->options.photo); });
      if (found == by_phase.end())
        ThrowError("--photo", "photo " + std::to_string(args->options.photo) + " has no samples");
      chosen = found->second;
      phase = found->first;
    }

    // The reconstruction and the truth, when the run has them.
    const std::string merl_path = (run_dir / "reconstruction" / "brdf.binary").string();
    std::unique_ptr<MerlTable> table;
    if (fs::exists(merl_path)) table = std::make_unique<MerlTable>(ReadMerl(merl_path));
    std::unique_ptr<BrdfModel> truth;
    std::string truth_path;
    const fs::path comparison = run_dir / "truth-comparison.json";
    if (fs::exists(comparison)) {
      const nlohmann::json json = ReadJsonFile(comparison.string());
      if (json.contains("truth") && json["truth"].is_string() && fs::exists(json["truth"].get<std::string>())) {
        truth_path = json["truth"].get<std::string>();
        truth = LoadTruthMaterial(truth_path);
      }
    }

    AtomicDirectory directory(out, args->overwrite);
    const fs::path tmp(directory.temporary_path());

    // The measured photo, cropped to the samples' pixel box, linearized and tone-mapped.
    const fs::path sidecar(SidecarPath(samples_path));
    std::string photo_note;
    if (fs::exists(sidecar)) {
      const nlohmann::json side = ReadJsonFile(sidecar.string());
      try {
        const Session session = Session::Load(side.at("session").get<std::string>());
        if (chosen >= session.photos.size())
          ThrowError(session.manifest_path, "has fewer photos than the samples name");
        const PhotoStats& p = photos[chosen];
        const int pad = std::max(4, (p.x1 - p.x0) / 8);
        Image photo = ReadImage(session.PhotoPath(chosen));
        LinearizeImage(session, chosen, &photo, /*divide_by_exposure=*/true);
        const int x0 = std::max(0, p.x0 - pad), y0 = std::max(0, p.y0 - pad);
        const int x1 = std::min(photo.width - 1, p.x1 + pad), y1 = std::min(photo.height - 1, p.y1 + pad);
        Image crop(x1 - x0 + 1, y1 - y0 + 1, 3);
        for (int y = y0; y <= y1; ++y) {
          for (int x = x0; x <= x1; ++x) {
            for (int c = 0; c < 3; ++c) {
              crop.at(x - x0, y - y0, c) = photo.at(x, y, std::min(c, photo.channels - 1));
            }
          }
        }
        WriteImage((tmp / "photo.png").string(), ToneMap(crop, nullptr), PixelFormat::kUint8);
        data["photo"] = {{"file", "photo.png"},      {"source", session.PhotoPath(chosen)}, {"index", chosen},
                         {"crop", {x0, y0, x1, y1}}, {"phase_deg", phase / kDeg},           {"samples", p.count}};
      } catch (const Error& e) {
        photo_note = e.what();
        Log(1, "report: no photo: " + photo_note);
      }
    }
    if (!photo_note.empty()) data["photo_note"] = photo_note;

    // Spheres of the reconstructed (and the true) material, lit at the chosen photo's phase angle.
    const int size = args->options.render_size;
    if (table) {
      const Image render = RenderSphere(
          size, phase, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return table->Lookup(wi, wo); });
      WriteImage((tmp / "render.png").string(), ToneMap(render, nullptr), PixelFormat::kUint8);
      data["render"] = {{"file", "render.png"}, {"phase_deg", phase / kDeg}};
    }
    if (truth) {
      const Image render = RenderSphere(
          size, phase, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return truth->Eval(wi, wo); });
      WriteImage((tmp / "render-truth.png").string(), ToneMap(render, nullptr), PixelFormat::kUint8);
      data["render_truth"] = {{"file", "render-truth.png"}, {"phase_deg", phase / kDeg}};
      data["truth"] = truth_path;
    }

    // The reconstruction and the truth along the incidence plane: theta_0 fixed, the other angle signed
    // (positive on the light's side, delta_phi = 0; negative on the mirror side, delta_phi = pi).
    nlohmann::json curves = nlohmann::json::array();
    for (const double theta0 : {15.0, 30.0, 45.0, 60.0}) {
      nlohmann::json angles = nlohmann::json::array(), recon = nlohmann::json::array(),
                     true_values = nlohmann::json::array();
      for (double x = -88.0; x <= 88.0; x += 0.5) {
        const Eigen::Vector3d wi(std::sin(theta0 * kDeg), 0.0, std::cos(theta0 * kDeg));
        const Eigen::Vector3d wo(std::sin(x * kDeg), 0.0, std::cos(x * kDeg));
        angles.push_back(x);
        if (table) {
          const Eigen::Vector3d f = table->Lookup(wi, wo);
          recon.push_back({f[0], f[1], f[2]});
        }
        if (truth) {
          const Eigen::Vector3d f = truth->Eval(wi, wo);
          true_values.push_back({f[0], f[1], f[2]});
        }
      }
      curves.push_back(
          {{"theta0_deg", theta0}, {"angle_deg", angles}, {"reconstruction", recon}, {"truth", true_values}});
    }
    data["incidence_plane"] = curves;
    WriteJsonFile((tmp / "report-data.json").string(), data);

    const int code = RunSubprocess({IBRDF_PYTHON, script, fs::absolute(run_dir).string(), tmp.string()});
    if (code != 0) {
      ThrowError(script, "the plotting script failed (exit " + std::to_string(code) +
                             "); its message is above (it needs Debian's python3-numpy and python3-matplotlib)");
    }
    RequireFile((tmp / "index.html").string(), script + ": wrote no index.html");
    directory.Commit();
    Log(1, "report written to " + (fs::path(out) / "index.html").string());
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(70, AddReportCommand);

}  // namespace ibrdf
