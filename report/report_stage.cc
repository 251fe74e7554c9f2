#include "report/report_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_brdf.h"
#include "core/npy.h"
#include "core/output_guard.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "core/statistics.h"
#include "radiometry/linear_image.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/prediction_check.h"
#include "reconstruct/truth_comparison.h"
#include "report/acquisition_thumbnails.h"
#include "report/light_photos.h"
#include "report/photo_comparison.h"
#include "report/photo_statistics.h"
#include "report/report_png.h"
#include "report/report_script.h"
#include "report/sphere_render.h"
#include "report/tone_map.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

constexpr double kBandThetaDeg = 2.5;  // |theta - theta_0| for "fixed" incidence or exitance
constexpr double kBandPhiDeg = 5.0;    // |delta_phi| or |180 - |delta_phi|| for "in the incidence plane"
constexpr size_t kBandSamples = 3000;  // per band and kind, an even subset beyond that

// A model the report evaluates: the reconstruction (smoothly interpolated table), the fits, the truth.
struct NamedModel {
  std::string name;
  BrdfEvalFunction eval;
};

// The reconstruction, the fits beside it and the truth, when the run has them.
struct RunModels {
  // The reconstruction as the report reads it: trilinear between cells (core/merl_brdf.h), whose
  // staircase of nearest cells would read as structure in a plot.
  std::unique_ptr<MerlBrdf> table;
  std::string table_path;
  std::vector<std::unique_ptr<BrdfModel>> fits;
  std::vector<std::string> fit_names;
  std::unique_ptr<BrdfModel> truth;
  std::string truth_path;
  std::vector<NamedModel> named;  // in drawing order
};

// The reconstruction folder or file asked for: a folder with brdf.binary, or the .binary itself.
std::string ReconstructionTable(const fs::path& run_dir, const std::string& given) {
  if (given.empty()) {
    const fs::path path = run_dir / "reconstruction" / "brdf.binary";
    return fs::exists(path) ? path.string() : "";
  }
  if (fs::is_directory(given)) {
    const fs::path path = fs::path(given) / "brdf.binary";
    if (!fs::is_regular_file(path))
      ThrowError(given, "is a folder without brdf.binary (not an `ibrdf reconstruct` output)");
    return path.string();
  }
  if (!fs::is_regular_file(given))
    ThrowError(given, "does not exist (--reconstruction: a reconstruction folder or its brdf.binary)");
  return given;
}

RunModels LoadRunModels(const fs::path& run_dir, const std::string& reconstruction) {
  RunModels models;
  models.table_path = ReconstructionTable(run_dir, reconstruction);
  if (!models.table_path.empty()) {
    models.table = std::make_unique<MerlBrdf>(models.table_path, MerlLookup::kLinear);
    const fs::path dir = fs::path(models.table_path).parent_path();
    for (const char* fit : {"lafortune", "ggx"}) {
      const fs::path path = dir / (std::string(fit) + ".json");
      if (!fs::is_regular_file(path)) continue;
      models.fits.push_back(LoadMaterial(path.string()));
      models.fit_names.push_back(fit);
    }
  }
  const fs::path comparison = run_dir / "truth-comparison.json";
  if (fs::exists(comparison)) {
    const nlohmann::json json = ReadJsonFile(comparison.string());
    if (json.contains("truth") && json["truth"].is_string() && fs::exists(json["truth"].get<std::string>())) {
      models.truth_path = json["truth"].get<std::string>();
      models.truth = LoadTruthMaterial(models.truth_path);
    }
  }
  if (models.table) {
    const MerlBrdf* table = models.table.get();
    models.named.push_back({"reconstruction", [table](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
                              if (wi.z() <= 0.0 || wo.z() <= 0.0) return Eigen::Vector3d(-1.0, -1.0, -1.0);
                              return table->Lookup(wi, wo);
                            }});
  }
  for (size_t i = 0; i < models.fits.size(); ++i) {
    const BrdfModel* fit = models.fits[i].get();
    models.named.push_back({models.fit_names[i],
                            [fit](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return fit->Eval(wi, wo); }});
  }
  if (models.truth) {
    const BrdfModel* truth = models.truth.get();
    models.named.push_back(
        {"truth", [truth](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return truth->Eval(wi, wo); }});
  }
  return models;
}

// The report's title: the option, else the recipe's name (the run's input, from run-input.json or
// summary.json), else the session's name unless it is a generator's default ("synth..."), else the run
// folder's name.
std::string ReportTitle(const fs::path& run_dir, const std::string& samples_path, const std::string& given) {
  if (!given.empty()) return given;
  std::string session_name;
  for (const char* name : {"run-input.json", "summary.json"}) {
    const fs::path path = run_dir / name;
    if (!fs::is_regular_file(path)) continue;
    const nlohmann::json json = ReadJsonFile(path.string());
    if (json.contains("input") && json["input"].is_string()) {
      const fs::path recipe = fs::path(json["input"].get<std::string>()) / "recipe.json";
      if (fs::is_regular_file(recipe)) {
        const nlohmann::json r = ReadJsonFile(recipe.string());
        if (r.contains("name") && r["name"].is_string()) return r["name"].get<std::string>();
      }
    }
    if (json.contains("session_name") && json["session_name"].is_string()) session_name = json["session_name"];
  }
  const fs::path sidecar(SidecarPath(samples_path));
  if (session_name.empty() && fs::is_regular_file(sidecar)) {
    const nlohmann::json side = ReadJsonFile(sidecar.string());
    if (side.contains("session_name") && side["session_name"].is_string()) session_name = side["session_name"];
  }
  if (!session_name.empty() && session_name.rfind("synth", 0) != 0) return session_name;
  return fs::absolute(run_dir).lexically_normal().filename().string();
}

Eigen::Vector3d Wi(const BrdfSample& s) { return Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(); }
Eigen::Vector3d Wo(const BrdfSample& s) { return Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized(); }

// A model's values at one photo's samples: a function of the directions, or given per sample.
struct PhotoModel {
  std::string name;
  BrdfEvalFunction eval;                // empty when `values` holds them
  std::vector<Eigen::Vector3d> values;  // per sample of the photo, in its order
};

// One photo at full resolution (cropped to its samples' box, linearized, tone-mapped) as
// PREFIX.png, and each model rendered at the photo's own pixels (PREFIX-render-MODEL.png, on the
// photo's tone scale) with its signed difference (PREFIX-diff-MODEL.npy). Returns the photo's data.
nlohmann::json RenderPhoto(const Session& session, uint32_t index, const PhotoStats& p,
                           const std::vector<const BrdfSample*>& own, const std::vector<PhotoModel>& models,
                           const std::string& prefix, const fs::path& tmp) {
  if (index >= session.photos.size()) ThrowError(session.manifest_path, "has fewer photos than the samples name");
  Image photo = ReadImage(session.PhotoPath(index));
  LinearizeImage(session, index, &photo, /*divide_by_exposure=*/true);
  const int pad = std::max(4, (p.x1 - p.x0) / 16);
  PixelBox box{std::max(0, p.x0 - pad), std::max(0, p.y0 - pad), std::min(photo.width - 1, p.x1 + pad),
               std::min(photo.height - 1, p.y1 + pad)};
  const Image crop = CropPhoto(photo, box);
  double scale = 1.0;
  WriteReportPng((tmp / (prefix + ".png")).string(), ToneMap(crop, &scale));
  nlohmann::json renders = nlohmann::json::array();
  for (const PhotoModel& model : models) {
    const PhotoRender render = model.eval ? RenderPhotoPixels(photo, box, own, model.name, model.eval)
                                          : RenderPhotoPixels(photo, box, own, model.name, model.values);
    const std::string png = prefix + "-render-" + model.name + ".png", npy = prefix + "-diff-" + model.name + ".npy";
    WriteReportPng((tmp / png).string(), ToneMapWithScale(render.linear, scale));
    WriteNpyArray((tmp / npy).string(), render.difference.pixels,
                  {size_t(render.difference.height), size_t(render.difference.width)});
    renders.push_back({{"model", model.name},
                       {"file", png},
                       {"difference", npy},
                       {"median_abs_difference", render.median_abs_difference}});
  }
  return {{"file", prefix + ".png"}, {"source", session.PhotoPath(index)},
          {"index", index},          {"crop", {box.x0, box.y0, box.x1, box.y1}},
          {"full_resolution", true}, {"stride", SampleStride(own)},
          {"samples", p.count},      {"renders", renders}};
}

// The samples' session, from the sample file's sidecar; `*note` says why not when it cannot be read.
std::optional<Session> SamplesSession(const std::string& samples_path, std::string* note) {
  const fs::path sidecar(SidecarPath(samples_path));
  if (!fs::exists(sidecar)) {
    *note = sidecar.string() + " is missing, so the samples' session (and photos) are unknown";
    return std::nullopt;
  }
  try {
    const nlohmann::json side = ReadJsonFile(sidecar.string());
    return Session::Load(side.at("session").get<std::string>());
  } catch (const Error& e) {
    *note = e.what();
  } catch (const nlohmann::json::exception& e) {
    *note = sidecar.string() + ": no session named (" + e.what() + ")";
  }
  return std::nullopt;
}

// True when `session` has a photo other than a PNG (TIFF, EXR, RAW ...): those decode through
// OpenImageIO (the report's own PNGs do not need it, report/report_png.h).
bool PhotosNeedImageModule(const Session& session) {
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (LowerExtension(session.PhotoPath(i)) != ".png") return true;
  }
  return false;
}

std::vector<const BrdfSample*> PhotoSamples(const std::vector<BrdfSample>& samples, uint32_t image) {
  std::vector<const BrdfSample*> own;
  for (const BrdfSample& s : samples) {
    if (s.image == image) own.push_back(&s);
  }
  return own;
}

// The measured photo at full resolution (cropped to the samples' box), and each model rendered at the
// photo's own pixels with its signed difference. Errors reading the samples' session become a note in
// the data instead of failing the report.
void WritePhoto(const std::optional<Session>& session, const std::vector<BrdfSample>& samples, const PhotoStats& p,
                const ChosenPhoto& chosen, const RunModels& models, const fs::path& tmp, nlohmann::json* data,
                ReportResult* result) {
  if (session) {
    try {
      std::vector<PhotoModel> photo_models;
      for (const NamedModel& model : models.named) photo_models.push_back({model.name, model.eval, {}});
      nlohmann::json photo =
          RenderPhoto(*session, chosen.photo, p, PhotoSamples(samples, chosen.photo), photo_models, "photo", tmp);
      photo["phase_deg"] = chosen.phase / kDegree;
      (*data)["photo"] = photo;
      result->photo_shown = true;
    } catch (const Error& e) {
      result->photo_note = e.what();
      Log(1, "report: no photo: " + result->photo_note);
    }
  }
  if (!result->photo_note.empty()) (*data)["photo_note"] = result->photo_note;
}

// The local regression's options of the reconstruction (its summary.json's "regression": degree, radii,
// binning, folds, log space), or the defaults when there is none.
LocalRegressionOptions ReconstructionRegression(const std::string& table_path) {
  LocalRegressionOptions options;
  if (table_path.empty()) return options;
  const fs::path summary = fs::path(table_path).parent_path() / "summary.json";
  if (!fs::is_regular_file(summary)) return options;
  const nlohmann::json json = ReadJsonFile(summary.string());
  if (!json.contains("regression") || !json["regression"].is_object()) return options;
  const nlohmann::json& r = json["regression"];
  options.degree = r.value("degree", options.degree);
  options.radius_h_deg = r.value("radius_h_deg", options.radius_h_deg);
  options.radius_d_deg = r.value("radius_d_deg", options.radius_d_deg);
  options.bin_fraction_h = r.value("bin_fraction_h", options.bin_fraction_h);
  options.bin_fraction_d = r.value("bin_fraction_d", options.bin_fraction_d);
  options.fold_reciprocity = r.value("fold_reciprocity", options.fold_reciprocity);
  options.fold_bilateral = r.value("fold_bilateral", options.fold_bilateral);
  options.log_space = r.value("log_space", options.log_space);
  std::string why;
  if (!options.Check(&why)) ThrowError(summary.string(), "\"regression\": " + why);
  return options;
}

// Held-out photos (the ones `ibrdf check --regression --held-out N` holds out): each photo beside the
// sample rendered from its camera by the local regression fitted WITHOUT that photo's samples (the
// reconstruction's options, evaluated at the photo's own directions rather than through the table), the
// reconstruction that saw it, and the signed differences. A photo that cannot be read is a note.
void WriteHeldOutPhotos(const std::optional<Session>& session, const std::vector<BrdfSample>& samples,
                        std::map<uint32_t, PhotoStats>& photos, int count, const RunModels& models, const fs::path& tmp,
                        nlohmann::json* data, ReportResult* result) {
  if (count <= 0 || !session) return;
  LocalRegressionOptions regression_options = ReconstructionRegression(models.table_path);
  // The held-out renders show the fit's values only: its per-cell standard errors (two more fits per
  // point) would double the report's time for nothing shown.
  regression_options.standard_errors = false;
  nlohmann::json held = nlohmann::json::array();
  // A figure written as JSON: NaN (no pixel had one) is null there.
  auto number = [](const nlohmann::json& value) { return value.is_number() ? value.get<double>() : double(NAN); };
  for (const uint32_t image : HeldOutImages(samples, count)) {
    try {
      Timer timer;
      // The fit leaves the photo's samples out by flag (copying the other 1.1 M samples of the demo
      // cost more than the flags).
      std::vector<uint8_t> leave_out(samples.size());
      size_t fit_samples = 0;
      for (size_t i = 0; i < samples.size(); ++i) {
        leave_out[i] = samples[i].image == image;
        fit_samples += !leave_out[i];
      }
      const std::vector<const BrdfSample*> own = PhotoSamples(samples, image);
      std::vector<Eigen::Vector3d> points;
      points.reserve(own.size());
      for (const BrdfSample* s : own) points.push_back(RegressionCoordinates(Wi(*s), Wo(*s)));
      ReliabilityCounts reliability;
      std::vector<Estimate> estimates;
      {
        const LocalRegression regression(samples, leave_out, regression_options);
        estimates = regression.EvaluateMany(points, &reliability);
      }
      std::vector<Eigen::Vector3d> values(own.size());
      size_t unsupported = 0;
      for (size_t i = 0; i < own.size(); ++i) {
        const bool supported = estimates[i].status != EstimateStatus::kUnsupported;
        values[i] = supported ? estimates[i].value : Eigen::Vector3d::Constant(NAN);
        unsupported += !supported;
      }
      std::vector<PhotoModel> photo_models = {{"held-out", {}, std::move(values)}};
      if (!models.named.empty() && models.named.front().name == "reconstruction")
        photo_models.push_back({"reconstruction", models.named.front().eval, {}});
      nlohmann::json photo =
          RenderPhoto(*session, image, photos[image], own, photo_models, "held-out-" + std::to_string(image), tmp);
      const std::vector<float>& phase = photos[image].phase;
      photo["phase_deg"] = phase.empty() ? 0.0 : Percentile(phase, 0.5) / kDegree;
      photo["fit_samples"] = fit_samples;
      photo["unsupported"] = unsupported;
      photo["seconds"] = timer.ElapsedSeconds();
      HeldOutRender shown;
      shown.image = image;
      shown.median_abs_difference = number(photo["renders"][0]["median_abs_difference"]);
      if (photo["renders"].size() > 1)
        shown.in_sample_median_abs_difference = number(photo["renders"][1]["median_abs_difference"]);
      result->held_out.push_back(shown);
      held.push_back(photo);
    } catch (const Error& e) {
      held.push_back({{"index", image}, {"note", e.what()}});
      Log(1, "report: held-out photo " + std::to_string(image) + " not shown: " + e.what());
    }
  }
  (*data)["held_out"] = held;
}

// Spheres of every model, lit at the chosen photo's phase angle.
void WriteSpheres(const RunModels& models, int size, double phase, const fs::path& tmp, nlohmann::json* data) {
  nlohmann::json spheres = nlohmann::json::array();
  for (const NamedModel& model : models.named) {
    const std::string file = "sphere-" + model.name + ".png";
    WriteReportPng((tmp / file).string(), ToneMap(RenderSphere(size, phase, model.eval), nullptr));
    spheres.push_back({{"model", model.name}, {"file", file}, {"phase_deg", phase / kDegree}});
  }
  (*data)["spheres"] = spheres;
  if (models.truth) (*data)["truth"] = models.truth_path;
}

// The models along the incidence plane, evaluated where the band's samples are: for each theta_0, the
// fixed-incidence samples (|theta_i - theta_0| <= 2.5 deg, within 5 deg of the plane; abscissa the
// signed theta_e, positive on the light's side) and the fixed-exitance ones (abscissa the signed
// theta_i), each with every model at the sample's own directions, in incidence-plane-K.npy (columns:
// kind (0 fixed incidence, 1 fixed exitance), abscissa deg, sample RGB, then RGB per model); and each
// model in the exact plane (the band's centre) for the dotted curves.
nlohmann::json IncidencePlanes(const std::vector<BrdfSample>& samples, const RunModels& models,
                               const std::vector<double>& angles, const fs::path& tmp, ReportResult* result) {
  nlohmann::json planes = nlohmann::json::array();
  std::vector<std::string> columns = {"kind", "abscissa_deg", "sample_r", "sample_g", "sample_b"};
  for (const NamedModel& m : models.named) {
    for (const char* c : {"_r", "_g", "_b"}) columns.push_back(m.name + c);
  }
  for (size_t k = 0; k < angles.size(); ++k) {
    const double t0 = angles[k];
    std::vector<const BrdfSample*> band[2];
    for (const BrdfSample& s : samples) {
      const double ti = s.theta_i / kDegree, te = s.theta_e / kDegree, dp = std::abs(s.delta_phi / kDegree);
      if (!(dp <= kBandPhiDeg || dp >= 180.0 - kBandPhiDeg)) continue;
      if (std::abs(ti - t0) <= kBandThetaDeg) band[0].push_back(&s);
      if (std::abs(te - t0) <= kBandThetaDeg) band[1].push_back(&s);
    }
    std::vector<float> rows;
    size_t n_rows = 0;
    std::vector<std::vector<double>> ratios(models.named.size() * 3);
    for (int kind = 0; kind < 2; ++kind) {
      const size_t step = std::max<size_t>(1, (band[kind].size() + kBandSamples - 1) / kBandSamples);
      for (size_t i = 0; i < band[kind].size(); i += step) {
        const BrdfSample& s = *band[kind][i];
        const bool light_side = std::abs(s.delta_phi / kDegree) <= kBandPhiDeg;
        const double other = (kind == 0 ? s.theta_e : s.theta_i) / kDegree;
        rows.push_back(float(kind));
        rows.push_back(float(light_side ? other : -other));
        // A channel the sample did not measure (clipped, under the noise floor: its `valid` flag) is NaN
        // in the file (not plotted) and left out of the ratios.
        for (int c = 0; c < 3; ++c) rows.push_back(s.Valid(c) ? s.brdf[c] : NAN);
        for (size_t m = 0; m < models.named.size(); ++m) {
          const Eigen::Vector3d f = models.named[m].eval(Wi(s), Wo(s));
          for (int c = 0; c < 3; ++c) {
            rows.push_back(f[c] >= 0.0 ? float(f[c]) : NAN);
            if (s.Valid(c) && f[c] > 0.0 && s.brdf[c] > 0.0f) ratios[m * 3 + c].push_back(s.brdf[c] / f[c]);
          }
        }
        ++n_rows;
      }
    }
    const std::string file = "incidence-plane-" + std::to_string(k) + ".npy";
    WriteNpyArray((tmp / file).string(), rows, {n_rows, columns.size()});
    // Each model in the exact plane.
    nlohmann::json centre = nlohmann::json::object();
    std::vector<double> abscissa;
    for (double x = -88.0; x <= 88.0; x += 0.5) abscissa.push_back(x);
    for (const NamedModel& m : models.named) {
      nlohmann::json values = nlohmann::json::array();
      for (const double x : abscissa) {
        const Eigen::Vector3d wi(std::sin(t0 * kDegree), 0.0, std::cos(t0 * kDegree));
        const Eigen::Vector3d wo(std::sin(x * kDegree), 0.0, std::cos(x * kDegree));
        const Eigen::Vector3d f = m.eval(wi, wo);
        values.push_back({f[0], f[1], f[2]});
      }
      centre[m.name] = values;
    }
    nlohmann::json agreement = nlohmann::json::object();
    for (size_t m = 0; m < models.named.size(); ++m) {
      BandAgreement a;
      a.theta0_deg = t0;
      a.model = models.named[m].name;
      a.samples = std::max({ratios[m * 3].size(), ratios[m * 3 + 1].size(), ratios[m * 3 + 2].size()});
      nlohmann::json rgb = nlohmann::json::array();
      for (int c = 0; c < 3; ++c) {
        a.ratio[c] = ratios[m * 3 + c].empty() ? NAN : Percentile(ratios[m * 3 + c], 0.5);
        rgb.push_back(std::isfinite(a.ratio[c]) ? nlohmann::json(a.ratio[c]) : nlohmann::json());
      }
      agreement[a.model] = {{"samples", a.samples}, {"median_sample_over_model", rgb}};
      if (a.model == "reconstruction") result->bands.push_back(a);
    }
    planes.push_back({{"theta0_deg", t0},
                      {"band_theta_deg", kBandThetaDeg},
                      {"band_phi_deg", kBandPhiDeg},
                      {"file", file},
                      {"columns", columns},
                      {"fixed_incidence_samples", band[0].size()},
                      {"fixed_exitance_samples", band[1].size()},
                      {"centre_abscissa_deg", abscissa},
                      {"centre", centre},
                      {"agreement", agreement}});
  }
  return planes;
}

// The explorer's grids, per model (float32 .npy, -1 where a model has no value):
//  explorer-curves-M.npy (theta_i 0..85 step 5, slice azimuth 0..180 step 15, signed theta_e -89..89
//    step 1, RGB): wi = (theta_i, phi 0); x >= 0 is wo at (x, phi), x < 0 at (-x, phi + 180);
//  explorer-halfdiff-M.npy (theta_h 0..89, theta_d 0..89 at 1 deg cell centres, phi_d 90 deg, RGB);
//  explorer-table-M.npy (32 x 32 x 32 cells, MERL's axes: theta_h on the square-root axis, theta_d,
//    phi_d over [0, 180), at cell centres, RGB) for the lit sphere.
nlohmann::json ExplorerGrids(const std::vector<BrdfSample>& samples, const RunModels& models, const fs::path& tmp) {
  nlohmann::json grids = {{"theta_i_deg", {0, 85, 5}},
                          {"phi_deg", {0, 180, 15}},
                          {"theta_e_deg", {-89, 89, 1}},
                          {"table_cells", 32},
                          {"models", nlohmann::json::array()}};
  auto value = [](const Eigen::Vector3d& f, std::vector<float>* out) {
    for (int c = 0; c < 3; ++c) out->push_back(std::isfinite(f[c]) && f[c] >= 0.0 ? float(f[c]) : -1.0f);
  };
  for (const NamedModel& m : models.named) {
    std::vector<float> curves, halfdiff, table;
    for (int ti = 0; ti <= 85; ti += 5) {
      for (int phi = 0; phi <= 180; phi += 15) {
        for (int x = -89; x <= 89; ++x) {
          const Eigen::Vector3d wi = FromSpherical(ti * kDegree, 0.0);
          const Eigen::Vector3d wo = FromSpherical(std::abs(x) * kDegree, (x >= 0 ? phi : phi + 180) * kDegree);
          value(m.eval(wi, wo), &curves);
        }
      }
    }
    for (int h = 0; h < 90; ++h) {
      for (int d = 0; d < 90; ++d) {
        HalfDiffAngles a;
        a.theta_h = (h + 0.5) * kDegree;
        a.theta_d = (d + 0.5) * kDegree;
        a.phi_d = 90.0 * kDegree;
        Eigen::Vector3d wi, wo;
        FromHalfDiff(a, &wi, &wo);
        value(wi.z() > 0.0 && wo.z() > 0.0 ? m.eval(wi, wo) : Eigen::Vector3d(-1, -1, -1), &halfdiff);
      }
    }
    constexpr int n = 32;
    for (int h = 0; h < n; ++h) {
      for (int d = 0; d < n; ++d) {
        for (int p = 0; p < n; ++p) {
          HalfDiffAngles a;
          const double u = (h + 0.5) / n;
          a.theta_h = u * u * kPi / 2.0;
          a.theta_d = (d + 0.5) / n * kPi / 2.0;
          a.phi_d = (p + 0.5) / n * kPi;
          Eigen::Vector3d wi, wo;
          FromHalfDiff(a, &wi, &wo);
          value(wi.z() > 0.0 && wo.z() > 0.0 ? m.eval(wi, wo) : Eigen::Vector3d(-1, -1, -1), &table);
        }
      }
    }
    const std::string prefix = "explorer-";
    WriteNpyArray((tmp / (prefix + "curves-" + m.name + ".npy")).string(), curves, {18, 13, 179, 3});
    WriteNpyArray((tmp / (prefix + "halfdiff-" + m.name + ".npy")).string(), halfdiff, {90, 90, 3});
    WriteNpyArray((tmp / (prefix + "table-" + m.name + ".npy")).string(), table, {n, n, n, 3});
    grids["models"].push_back(m.name);
  }
  // A fixed-stride subset of the samples: theta_i, theta_e, delta_phi (deg), RGB.
  std::vector<float> subset;
  const size_t step = std::max<size_t>(1, samples.size() / 40000);
  size_t rows = 0;
  for (size_t i = 0; i < samples.size(); i += step, ++rows) {
    const BrdfSample& s = samples[i];
    for (const float v : {float(s.theta_i / kDegree), float(s.theta_e / kDegree), float(s.delta_phi / kDegree),
                          s.brdf[0], s.brdf[1], s.brdf[2]}) {
      subset.push_back(v);
    }
  }
  WriteNpyArray((tmp / "explorer-samples.npy").string(), subset, {rows, 6});
  grids["samples"] = rows;
  return grids;
}

}  // namespace

bool ReportOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(render_size_px, 16, 4096);
  IBRDF_CHECK_OPTION_RANGE(held_out_photos, 0, 16);
  IBRDF_CHECK_OPTION(!angles_deg.empty() && angles_deg.size() <= 8);
  for (const double angle : angles_deg) {
    if (!(angle >= 0.0 && angle <= 85.0)) {
      *why = "angles_deg: every incidence-plane angle must be in [0, 85] degrees";
      return false;
    }
  }
  return true;
}

namespace {
// `fraction` as a percentage, or "no data" where it is NaN (nothing to compare).
std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "no data";
  std::ostringstream out;
  out << 100.0 * fraction << " %";
  return out.str();
}
}  // namespace

std::string BandAgreement::BriefReport() const {
  std::ostringstream out;
  out << "incidence plane " << theta0_deg << " deg: ";
  if (samples == 0 || !std::isfinite(ratio[0]) || !std::isfinite(ratio[1]) || !std::isfinite(ratio[2])) {
    out << "no samples to compare with the " << (model.empty() ? std::string("reconstruction") : model);
    return out.str();
  }
  char line[160];
  std::snprintf(line, sizeof(line), "median sample / reconstruction R G B %.3f %.3f %.3f over %zu samples", ratio[0],
                ratio[1], ratio[2], samples);
  return out.str() + line;
}

std::string ReportResult::BriefReport() const {
  std::ostringstream out;
  out << "report \"" << title << "\": " << (success ? index_html : "FAILED") << ", " << samples << " samples, photo "
      << photo << " (" << phase_deg << " deg phase" << (photo_shown ? ", shown" : ", not shown") << ")"
      << (reconstruction ? ", reconstruction" : "") << (truth ? ", truth" : "");
  for (const std::string& fit : fits) out << ", " << fit << " fit";
  for (const HeldOutRender& h : held_out) {
    out << "; held-out photo " << h.image << ": median |render - photo| / photo " << Percent(h.median_abs_difference)
        << " (the reconstruction that saw it: "
        << (std::isfinite(h.in_sample_median_abs_difference) ? Percent(h.in_sample_median_abs_difference)
                                                              : std::string("none, the run has no brdf.binary"))
        << ")";
  }
  return out.str();
}

std::vector<std::string> ReportResult::SummaryLines() const {
  std::vector<std::string> lines = {BriefReport()};
  for (const BandAgreement& band : bands) lines.push_back(band.BriefReport());
  if (!explorer_html.empty()) lines.push_back("explorer: " + explorer_html);
  return lines;
}

std::vector<std::string> ReportInputs(const std::string& run_dir, const ReportOptions& options) {
  const fs::path own_report = fs::path(run_dir) / "report";
  std::vector<std::string> inputs = {run_dir};
  if (!options.reconstruction.empty()) inputs.push_back(options.reconstruction);
  for (const std::string& file : FilesUnder(run_dir)) {
    if (fs::path(file).lexically_relative(own_report).string().rfind("..", 0) != 0) continue;
    inputs.push_back(file);
  }
  return inputs;
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
  AtomicDirectory directory(out, options.overwrite);
  const fs::path tmp(directory.temporary_path());
  // The script starts now (matplotlib's import and the figures of the run folder alone beside the work
  // below) and draws the rest once report-data.json is written; destroyed before `directory`.
  BackgroundReportScript plotting(python, script, run_dir.string(), tmp.string());
  // The samples' session, read once; OpenImageIO's module, when its photos need it, loads beside the
  // reading below instead of at the first photo.
  std::string photo_note;
  const std::optional<Session> session = SamplesSession(samples_path, &photo_note);
  const std::future<void> image_module = std::async(std::launch::async, [&session] {
    if (session && PhotosNeedImageModule(*session)) PreloadImageModule();
  });
  const RunModels models = LoadRunModels(run_dir, options.reconstruction);

  const std::vector<BrdfSample> samples = ReadSamples(samples_path);
  if (samples.empty()) ThrowError(samples_path, "holds no samples");
  ReportResult result;
  result.samples = samples.size();
  result.title = ReportTitle(run_dir, samples_path, options.title);
  nlohmann::json data = {{"format", "ibrdf-report-data"}, {"version", 2}, {"title", result.title}};
  // The photo: the one whose median angle between light and view is the median over photos.
  std::map<uint32_t, PhotoStats> photos = CollectPhotoStats(samples);
  const ChosenPhoto chosen = ChoosePhoto(photos, options.photo);
  result.photo = chosen.photo;
  result.phase_deg = chosen.phase / kDegree;
  result.reconstruction = models.table != nullptr;
  result.reconstruction_path = models.table_path;
  result.fits = models.fit_names;
  result.truth = models.truth != nullptr;
  if (models.table) data["reconstruction"] = models.table_path;
  data["fits"] = models.fit_names;
  nlohmann::json names = nlohmann::json::array();
  for (const NamedModel& m : models.named) names.push_back(m.name);
  data["models"] = names;

  result.photo_note = photo_note;
  WritePhoto(session, samples, photos[chosen.photo], chosen, models, tmp, &data, &result);
  WriteHeldOutPhotos(session, samples, photos, options.held_out_photos, models, tmp, &data, &result);
  // Multi-light sessions (a dome, a turntable): the lights and a photo under each.
  const nlohmann::json lights = WriteLightPhotos(samples_path, photos, tmp.string());
  if (!lights.is_null()) data["lights"] = lights;
  // Each measurement photo (an even subset) with the sample's outline: the poses and the sample at a glance.
  if (session) data["acquisition_thumbnails"] = WriteAcquisitionThumbnails(*session, photos, tmp.string());
  WriteSpheres(models, options.render_size_px, chosen.phase, tmp, &data);
  data["incidence_plane"] = IncidencePlanes(samples, models, options.angles_deg, tmp, &result);
  if (options.explorer) data["explorer"] = ExplorerGrids(samples, models, tmp);
  WriteJsonFile((tmp / "report-data.json").string(), data);
  plotting.Finish();
  if (options.explorer) RequireFile((tmp / "explorer.html").string(), script + ": wrote no explorer.html");
  directory.Commit();
  result.index_html = (fs::path(out) / "index.html").string();
  if (options.explorer) result.explorer_html = (fs::path(out) / "explorer.html").string();
  Log(1, "report written to " + result.index_html);
  result.success = true;
  return result;
}

}  // namespace ibrdf
