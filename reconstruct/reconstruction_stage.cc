#include "reconstruct/reconstruction_stage.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/merl_brdf.h"
#include "core/npy.h"
#include "core/rgl_bsdf.h"
#include "core/tensor_file.h"
#include "reconstruct/sample_domain.h"
#include "reconstruct/truth_comparison.h"

namespace ibrdf {
namespace {

// What the stage reads besides the samples: the evaluation points and the truth.
struct StageInputs {
  std::vector<Eigen::Vector3d> eval_wi, eval_wo;
  std::vector<double> eval_theta_d;
  std::unique_ptr<BrdfModel> truth;
};

// A truth file: truth.json of a synthetic session (the "ibrdf-truth" wrapper), a material file or a
// MERL table.
std::unique_ptr<BrdfModel> LoadTruth(const std::string& path) { return LoadTruthFile(path); }

// Reads the evaluation points (theta_i, theta_e, delta_phi) into direction pairs.
void LoadEvalPoints(const std::string& eval_file, StageInputs* inputs) {
  std::vector<size_t> shape;
  const std::vector<double> points = ReadNpyArray(eval_file, &shape, true);
  if (shape.size() != 2 || shape[1] != 3) ThrowError(eval_file, "expected a float64 array of shape (N, 3)");
  inputs->eval_wi.resize(shape[0]);
  inputs->eval_wo.resize(shape[0]);
  inputs->eval_theta_d.resize(shape[0]);
  for (size_t i = 0; i < shape[0]; ++i) {
    // Validated where read: a point outside the angles' ranges would be answered, wrongly.
    if (!(points[3 * i] >= 0 && points[3 * i] <= M_PI / 2 && points[3 * i + 1] >= 0 && points[3 * i + 1] <= M_PI / 2 &&
          std::abs(points[3 * i + 2]) <= M_PI)) {
      ThrowError(eval_file,
                 "row " + std::to_string(i) + ": expected theta_i, theta_e in [0, pi/2] and delta_phi in [-pi, pi]");
    }
    inputs->eval_wi[i] = FromSpherical(points[3 * i], 0.0);
    inputs->eval_wo[i] = FromSpherical(points[3 * i + 1], points[3 * i + 2]);
    HalfDiffAngles angles;
    ToHalfDiff(inputs->eval_wi[i], inputs->eval_wo[i], &angles);
    inputs->eval_theta_d[i] = angles.theta_d;
  }
}

// Checks the options and reads the eval and truth files (before the samples, as the command always did).
StageInputs LoadInputs(const ReconstructOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("reconstruct options", why);
  StageInputs inputs;
  if (!options.eval_file.empty()) LoadEvalPoints(options.eval_file, &inputs);
  if (!options.truth_file.empty()) inputs.truth = LoadTruth(options.truth_file);
  return inputs;
}

void WriteText(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path());
    out << text;
    if (!out) ThrowError(path, "write failed");
  }
  file.Commit();
}

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes, const std::vector<size_t>& shape) {
  WriteNpy(path, "'|u1'", shape, 1, bytes.data(), bytes.size());
}

// Evaluates the regression at the eval points into eval.npy and eval_domain.npy (and the truth into
// eval_truth.npy): unmeasured points are -1 unless the fill mode gives them a value.
void EvaluatePoints(const LocalRegression& regression, const StageInputs& inputs, const ReconstructOptions& options,
                    const BrdfModel* fill_model, const std::string& tmp, nlohmann::json* summary,
                    nlohmann::json* timings) {
  Timer timer;
  const size_t n = inputs.eval_wi.size();
  std::vector<Eigen::Vector3d> uvw(n);
  for (size_t i = 0; i < n; ++i) uvw[i] = RegressionCoordinates(inputs.eval_wi[i], inputs.eval_wo[i]);
  ReliabilityCounts counts;
  const std::vector<Estimate> estimates = regression.EvaluateMany(uvw, &counts);
  std::vector<double> values(3 * n, -1.0), true_values;
  std::vector<float> uncertainty(3 * n, -1.0f);  // the regression's standard error where it gave the value
  std::vector<uint8_t> classes(n);
  DomainCounts domain;
  const FillMode fill = options.tabulate.fill;
  for (size_t i = 0; i < n; ++i) {
    const Estimate& e = estimates[i];
    DomainClass c = ClassifyEstimate(e, inputs.eval_theta_d[i], regression, options.tabulate.domain);
    if (e.effective_samples < options.tabulate.min_effective_samples) c = DomainClass::kUnmeasured;
    classes[i] = static_cast<uint8_t>(c);
    domain.Add(c);
    Eigen::Vector3d value = e.value;
    bool has_value = c != DomainClass::kUnmeasured;
    if (!has_value && fill == FillMode::kExtrapolate && e.status != EstimateStatus::kUnsupported) {
      has_value = true;
    } else if (!has_value && fill == FillMode::kModel && fill_model) {
      value = fill_model->Eval(inputs.eval_wi[i], inputs.eval_wo[i]);
      has_value = value.allFinite();
    }
    if (!has_value) continue;
    const bool regression_value = c != DomainClass::kUnmeasured || fill == FillMode::kExtrapolate;
    if (c == DomainClass::kUnmeasured) ++domain.filled;
    for (int ch = 0; ch < 3; ++ch) {
      values[3 * i + ch] = value[ch];
      if (regression_value) uncertainty[3 * i + ch] = e.standard_error[ch];
    }
  }
  (*timings)["eval_s"] = timer.ElapsedSeconds();
  WriteNpyArray(tmp + "/eval.npy", values, {n, 3});
  WriteBytes(tmp + "/eval_domain.npy", classes, {n});
  WriteNpyArray(tmp + "/eval_uncertainty.npy", uncertainty, {n, 3});
  if (inputs.truth) {
    true_values.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d f = inputs.truth->Eval(inputs.eval_wi[i], inputs.eval_wo[i]);
      for (int c = 0; c < 3; ++c) true_values[3 * i + c] = f[c];
    }
    WriteNpyArray(tmp + "/eval_truth.npy", true_values, {n, 3});
  }
  (*summary)["eval"] = {{"points", n},
                        {"file", options.eval_file},
                        {"reliability", ToJson(counts)},
                        {"domain", ToJson(domain)},
                        {"fill", FillModeName(fill)}};
  Log(1, "evaluated " + std::to_string(n) + " points: " + domain.Brief() + "; " + counts.Brief());
}

// Median and 95th percentile of `values` (sorted in place); zeros when empty.
std::pair<double, double> MedianP95(std::vector<float>* values) {
  if (values->empty()) return {0.0, 0.0};
  std::sort(values->begin(), values->end());
  auto at = [values](double q) { return double((*values)[size_t(q * double(values->size() - 1))]); };
  return {at(0.5), at(0.95)};
}

// The standard errors' figures by class (the largest channel's per cell), for summary.json and brdf.json.
nlohmann::json UncertaintyFigures(const std::vector<uint8_t>& domain, const std::vector<float>& uncertainty,
                                  const ReconstructOptions& options) {
  std::vector<float> by_class[3];
  for (size_t flat = 0; flat < domain.size(); ++flat) {
    if (uncertainty[3 * flat] < 0.0f) continue;
    const float e = std::max({uncertainty[3 * flat], uncertainty[3 * flat + 1], uncertainty[3 * flat + 2]});
    by_class[std::min<int>(domain[flat], 2)].push_back(e);
  }
  nlohmann::json json = {
      {"file", "uncertainty.npy"},
      {"meaning",
       "float32 (90, 90, 180, 3): one-sigma standard error of log f per channel (relative error of f), noise and "
       "bias of the local fit; -1 where the cell holds no value or a model's, inf where no error could be stated"},
      {"max_measured_standard_error", options.tabulate.domain.max_measured_standard_error},
      {"bias_shrink", options.regression.bias_shrink}};
  for (int c = 0; c < 3; ++c) {
    const auto [median, p95] = MedianP95(&by_class[c]);
    json[DomainClassName(static_cast<DomainClass>(c))] = {
        {"cells", by_class[c].size()}, {"median", median}, {"p95", p95}};
  }
  return json;
}

std::string UncertaintyBrief(const nlohmann::json& figures) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "measured cells median %.2f %%, p95 %.2f %%; interpolated median %.2f %%, p95 %.2f %% (largest channel; "
                "measured requires <= %.1f %%)",
                100.0 * figures["measured"]["median"].get<double>(), 100.0 * figures["measured"]["p95"].get<double>(),
                100.0 * figures["interpolated"]["median"].get<double>(),
                100.0 * figures["interpolated"]["p95"].get<double>(),
                100.0 * figures["max_measured_standard_error"].get<double>());
  return buffer;
}

// What WriteTable writes besides the table and its domain.
struct TableFiles {
  std::vector<float> effective_samples;  // per cell
  std::vector<float> uncertainty;        // per cell and channel: the standard error (uncertainty.npy)
  nlohmann::json sidecar;                // brdf.json
};

// The MERL table and its domain (into `table_out`, `domain_out`), its summary and its sidecar
// (`files`, written by WriteTable).
void Tabulate(const LocalRegression& regression, const ReconstructOptions& options, const BrdfModel* fill_model,
              ReconstructResult* result, nlohmann::json* timings, MerlTable* table_out,
              std::vector<uint8_t>* domain_out, TableFiles* files) {
  nlohmann::json& summary = result->summary;
  TabulateSummary tabulated;
  std::vector<float>& ess = files->effective_samples;
  std::vector<uint8_t>& domain = *domain_out;
  *table_out = TabulateMerl(regression, options.tabulate, &tabulated, &ess, &domain, fill_model, &files->uncertainty);
  (*timings)["tabulate_s"] = tabulated.seconds;
  Log(1, "regression: " + std::to_string(regression.size()) + " samples in " + std::to_string(regression.points()) +
             " points, " + tabulated.reliability.Brief());
  Log(1, tabulated.BriefReport());
  if (tabulated.domain.unmeasured > 0) {
    Log(1, std::to_string(tabulated.domain.unmeasured) + " cells are unmeasured (no samples around them): " +
               (options.tabulate.fill == FillMode::kNone
                    ? std::string("written as -1, MERL's \"no data\" (--fill model|extrapolate fills them)")
                    : std::to_string(tabulated.domain.filled) + " of them filled by --fill " +
                          FillModeName(options.tabulate.fill) + ": invented values, recorded in brdf.json"));
  }
  nlohmann::json table_json = {{"cells_measured", tabulated.domain.measured},
                               {"cells_interpolated", tabulated.domain.interpolated},
                               {"cells_unmeasured", tabulated.domain.unmeasured},
                               {"cells_unmeasured_filled", tabulated.domain.filled},
                               {"cells_beyond_theta_limit", tabulated.cells_below_horizon},
                               {"max_theta_deg", options.tabulate.max_theta_deg},
                               {"samples_theta_d_deg", {tabulated.theta_d_min_deg, tabulated.theta_d_max_deg}},
                               {"fill", FillModeName(options.tabulate.fill)},
                               {"domain_rules",
                                {{"measured_nearest_kernel_radii", options.tabulate.domain.measured_nearest},
                                 {"max_centroid_offset_kernel_radii", options.tabulate.domain.max_centroid_offset},
                                 {"theta_d_margin_deg", options.tabulate.domain.theta_d_margin_deg},
                                 {"max_measured_standard_error", options.tabulate.domain.max_measured_standard_error}}}};
  table_json["uncertainty"] = UncertaintyFigures(domain, files->uncertainty, options);
  Log(1, "standard errors (uncertainty.npy): " + UncertaintyBrief(table_json["uncertainty"]));
  if (!tabulated.fill_model.empty()) table_json["fill_model"] = tabulated.fill_model;
  files->sidecar = {
      {"format", "ibrdf-merl-table"},
      {"version", 1},
      {"files", {"brdf.binary", "brdf.npy", "domain.npy", "effective_samples.npy", "uncertainty.npy"}},
      {"domain_classes", {{"0", "unmeasured"}, {"1", "interpolated"}, {"2", "measured"}}},
      {"unmeasured_value", options.tabulate.fill == FillMode::kNone
                               ? "-1 (MERL's no data)"
                               : std::string("filled by ") + FillModeName(options.tabulate.fill) +
                                     " where possible (domain.npy 0 with a value >= 0: invented), else -1"},
      {"table", table_json},
      {"colour_space", summary.value("colour_space", nlohmann::json())},
      {"colour", summary.value("colour", nlohmann::json())}};
  summary["regression"]["reliability"] = ToJson(tabulated.reliability);
  summary["table"] = table_json;
  result->tabulated = true;
  result->cells_measured = tabulated.domain.measured;
  result->cells_interpolated = tabulated.domain.interpolated;
  result->cells_unmeasured = tabulated.domain.unmeasured;
  result->cells_filled = tabulated.domain.filled;
}

// brdf.binary, brdf.npy, effective_samples.npy, domain.npy and brdf.json into `tmp`; returns the seconds.
double WriteTable(const MerlTable& table, const std::vector<uint8_t>& domain, const TableFiles& files,
                  const std::string& tmp) {
  const Timer timer;
  WriteMerl(tmp + "/brdf.binary", table);
  WriteNpyArray(tmp + "/brdf.npy", MerlToArray(table), {90, 90, 180, 3});
  WriteNpyArray(tmp + "/effective_samples.npy", files.effective_samples, {90, 90, 180});
  WriteNpyArray(tmp + "/uncertainty.npy", files.uncertainty, {90, 90, 180, 3});
  WriteBytes(tmp + "/domain.npy", domain, {90, 90, 180});
  WriteJsonFile(tmp + "/brdf.json", files.sidecar);
  return timer.ElapsedSeconds();
}

// The table scored against the truth over the valid cells (measured or interpolated), the measured ones
// alone and every cell holding a value (filled ones included), and random MERL lookups; into `summary`
// (its own object: this runs beside the .bsdf export) and `result`'s score.
void Score(const MerlTable& table, const std::vector<uint8_t>& domain, const std::vector<float>& uncertainty,
           const BrdfModel& truth, const ReconstructOptions& options, nlohmann::json* summary,
           ReconstructResult* result) {
  std::vector<uint8_t> measured_only(domain.size()), interpolated_only(domain.size());
  for (size_t i = 0; i < domain.size(); ++i) {
    measured_only[i] = domain[i] == uint8_t(DomainClass::kMeasured);
    interpolated_only[i] = domain[i] == uint8_t(DomainClass::kInterpolated);
  }
  UncertaintyCoverage coverage_measured, coverage_interpolated;
  MerlLookupCheck lookups;
  std::vector<ReconstructionError> errors;
  tbb::task_group group;
  group.run([&] { lookups = CheckMerlLookups(table, truth); });
  group.run([&] {
    coverage_measured =
        CompareUncertaintyWithTruth(table, uncertainty, domain, uint8_t(DomainClass::kMeasured), truth, 80.0);
    coverage_interpolated =
        CompareUncertaintyWithTruth(table, uncertainty, domain, uint8_t(DomainClass::kInterpolated), truth, 80.0);
  });
  errors = CompareTableWithTruth(table, truth, 80.0, {&domain, &measured_only, nullptr, &interpolated_only});
  group.wait();
  const ReconstructionError& error = errors[0];
  (*summary)["error_against_truth"] = ToJson(error);
  (*summary)["error_against_truth"]["truth"] = options.truth_file;
  (*summary)["error_against_truth"]["domain"] =
      "theta_i, theta_e <= 80 deg; cells measured or interpolated (domain.npy)";
  Log(1, "against the truth (theta <= 80, measured and interpolated cells): " + error.Brief());
  (*summary)["error_against_truth_measured"] = ToJson(errors[1]);
  (*summary)["error_against_truth_all_tabulated"] = ToJson(errors[2]);
  (*summary)["error_against_truth_interpolated"] = ToJson(errors[3]);
  Log(1, "against the truth by class (theta <= 80): measured " + errors[1].Brief() + "; interpolated " +
             errors[3].Brief());
  (*summary)["uncertainty_coverage"] = {{"measured", ToJson(coverage_measured)},
                                        {"interpolated", ToJson(coverage_interpolated)},
                                        {"domain", "theta_i, theta_e <= 80 deg; |log(f / f_true)| against the "
                                                   "cell's standard error (uncertainty.npy), every channel"}};
  Log(1, "standard errors against the truth, measured cells: " + coverage_measured.Brief());
  Log(1, "standard errors against the truth, interpolated cells: " + coverage_interpolated.Brief());
  Log(1, "against the truth (theta <= 80, every cell holding a value): " + errors[2].Brief());
  (*summary)["merl_lookups_against_truth"] = ToJson(lookups);
  Log(1, lookups.Brief());
  result->scored = true;
  result->error_against_truth = error;
}

// A name for the fitted materials: the samples' session folder, else the samples file's stem; letters,
// digits, '-' and '_' only.
std::string MaterialName(const ReconstructOptions& options, const std::string& samples_file) {
  namespace fs = std::filesystem;
  std::string name = options.name;
  if (name.empty() && !samples_file.empty()) {
    name = fs::path(samples_file).stem().string();
    const std::string sidecar = SidecarPath(samples_file);
    std::error_code ec;
    if (fs::is_regular_file(sidecar, ec)) {
      try {
        const nlohmann::json json = ReadJsonFile(sidecar);
        if (json.contains("session") && json["session"].is_string()) {
          const std::string folder = fs::path(json["session"].get<std::string>()).parent_path().filename().string();
          if (!folder.empty()) name = folder;
        }
      } catch (const Error&) {
        // The sidecar is the derenderer's business; a name is a courtesy.
      }
    }
  }
  if (name.empty()) name = "ibrdf_fit";
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return name;
}

// The Lafortune and GGX fits, their material files and renderer snippets; returns the chosen model, the
// plausible fit (ModelFitResult::plausible) with the lower relative RMS against the samples, or null
// where neither is plausible; the summary says which fit was rejected and why. `colour_space` (the
// samples' own, from their sidecar) is stated in every material file and snippet.
std::unique_ptr<BrdfModel> FitModels(const std::vector<BrdfSample>& samples, const ModelFitOptions& fit_options,
                                     const std::string& name, const std::string& colour_space, bool relative_scale,
                                     const std::string& tmp, ReconstructResult* result, nlohmann::json* timings) {
  Timer timer;
  ModelFitOptions options = fit_options;
  options.relative_scale = relative_scale;
  // The two fits side by side (each runs its starts in parallel too).
  ModelFitResult lafortune, ggx;
  tbb::task_group group;
  group.run([&] {
    lafortune = FitLafortune(samples, options);
    Log(1, lafortune.BriefReport());
    WriteJsonFile(tmp + "/lafortune.json", FitMaterialJson(lafortune, name + "-lafortune", colour_space, relative_scale));
  });
  ggx = FitGgx(samples, options);
  Log(1, ggx.BriefReport());
  WriteJsonFile(tmp + "/ggx.json", FitMaterialJson(ggx, name + "-ggx", colour_space, relative_scale));
  group.wait();
  const RendererSnippets snippets = RendererMaterials(ggx, name, colour_space);
  WriteText(tmp + "/" + snippets.pbrt_file, snippets.pbrt);
  WriteText(tmp + "/" + snippets.mitsuba_file, snippets.mitsuba);
  (*timings)["fits_s"] = timer.ElapsedSeconds();
  ModelFitResult* chosen = nullptr;
  nlohmann::json rejected = nlohmann::json::object();
  for (ModelFitResult* fit : {&lafortune, &ggx}) {
    if (!fit->plausible) {
      std::string why;
      for (const std::string& reason : fit->implausible) why += (why.empty() ? "" : "; ") + reason;
      rejected[fit->model] = why;
      Log(1, "the " + fit->model + " fit is not chosen: not plausible (" + why + ")");
      continue;
    }
    if (!chosen || fit->rel_rms < chosen->rel_rms) chosen = fit;
  }
  result->summary["fits"] = {{"lafortune", ToJson(lafortune)},
                             {"ggx", ToJson(ggx)},
                             {"chosen", chosen ? chosen->model : "none"},
                             {"rejected", rejected},
                             {"renderer_snippets", {snippets.pbrt_file, snippets.mitsuba_file}},
                             {"snippet_kind", snippets.kind}};
  result->fitted = true;
  result->lafortune_rel_rms = lafortune.rel_rms;
  result->ggx_rel_rms = ggx.rel_rms;
  result->chosen_model = chosen ? chosen->model : "none";
  if (!chosen) {
    Log(0, "no fit chosen: neither the Lafortune nor the GGX fit is plausible (fits.rejected in summary.json)");
    return nullptr;
  }
  Log(1, "chosen model: " + result->chosen_model + " (the plausible fit of lower relative RMS against the samples, " +
             std::to_string(100.0 * chosen->rel_rms) + " %)");
  return std::move(chosen->brdf);
}

// The .bsdf file's description: what it was made from, and how many nodes were measured,
// interpolated, or unmeasured and filled how.
std::string BsdfDescription(const std::string& name, const std::string& samples_file, const DomainCounts& classes,
                            const BrdfModel* chosen, uint64_t filled_extrapolated, uint64_t zero,
                            std::vector<float> measured_errors) {
  const uint64_t nodes = classes.measured + classes.interpolated + classes.unmeasured;
  auto percent = [nodes](uint64_t n) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.1f", nodes ? 100.0 * double(n) / double(nodes) : 0.0);
    return std::string(buffer);
  };
  std::ostringstream text;
  text << "ibrdf reconstruct: the isotropic RGB BRDF of " << name << " from "
       << (samples_file.empty() ? std::string("samples") : samples_file)
       << " by local polynomial regression (Marschner et al. 1999); tables after Dupuy and Jakob 2018 (NDF from"
          " retro-reflection). Of the "
       << nodes << " BRDF nodes, " << classes.measured << " measured, " << classes.interpolated << " interpolated, "
       << classes.unmeasured << " (" << percent(classes.unmeasured) << " %) unmeasured: ";
  if (!classes.unmeasured) {
    text << "none";
  } else if (chosen) {
    text << "filled with the " << chosen->ModelName() << " fit (invented values)";
  } else {
    text << filled_extrapolated << " filled with the regression's extrapolation (invented values), " << zero
         << " set to 0 (no estimate, no fit)";
  }
  // The format has no uncertainty field: the standard errors are stated here and tabulated beside the
  // MERL table.
  const auto [median, p95] = MedianP95(&measured_errors);
  char errors[320];
  std::snprintf(errors, sizeof(errors),
                ". Stated standard error of the measured nodes (largest channel, noise and bias of the local fit): "
                "median %.2f %%, 95th percentile %.2f %%; per cell in uncertainty.npy beside the MERL table",
                100.0 * median, 100.0 * p95);
  text << errors;
  text << ". Spectra: a box-like upsampling of the RGB (not colour-exact); the rgb field is exact.";
  return text.str();
}

std::string Percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f %%", 100.0 * fraction);
  return text;
}

std::string BandFigures(double median, double p99, double max) {
  return "median " + Percent(median) + ", p99 " + Percent(p99) + ", max " + Percent(max);
}

// The written file, read back as a reader does, over the table's measured cells (theta <= 80 degrees,
// a sample of at most ~200 000 cells), each channel: its relative error against the table, and its
// reciprocity |f(wi, wo) - f(wo, wi)| / their mean (the table is reciprocal by construction, the
// file's interpolation in its warped grids is not), all cells and by theta_max band (0-25, 25-50,
// 50-80 degrees), each list sorted.
struct TableReadBack {
  std::vector<double> errors, reciprocity;
  std::vector<std::vector<double>> band_errors, band_reciprocity;
  // The worst cell against the table: file / table there, and where (theta_i, theta_e, delta_phi, degrees).
  double worst_ratio = 1.0;
  Eigen::Vector3d worst_at_deg = Eigen::Vector3d::Zero();
};

TableReadBack CompareWithTable(const RglBsdf& written, const MerlTable& table, const std::vector<uint8_t>& domain) {
  std::vector<size_t> cells;
  for (size_t flat = 0; flat < domain.size(); ++flat) {
    if (domain[flat] == uint8_t(DomainClass::kMeasured)) cells.push_back(flat);
  }
  const size_t stride = std::max<size_t>(1, cells.size() / 200000);
  // Each checked cell's band (-1: beyond 80 degrees), relative errors and reciprocity (-1: no positive
  // table value), TBB-parallel; gathered in cell order after.
  const size_t checked = (cells.size() + stride - 1) / stride;
  std::vector<int8_t> cell_band(checked, -1);
  std::vector<Eigen::Vector3d> cell_errors(checked), cell_reciprocity(checked);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, checked, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t m = range.begin(); m != range.end(); ++m) {
      const size_t flat = cells[m * stride];
      const int i_h = int(flat / (size_t(kMerlThetaD) * kMerlPhiD)), i_d = int(flat / kMerlPhiD % kMerlThetaD),
                i_p = int(flat % kMerlPhiD);
      Eigen::Vector3d wi, wo;
      FromHalfDiff(MerlCellCentre(i_h, i_d, i_p), &wi, &wo);
      const double theta_max = std::acos(std::min(wi.z(), wo.z())) * 180 / M_PI;
      if (theta_max > 80.0) continue;
      const Eigen::Vector3d t = table.Cell(flat), g = written.Eval(wi, wo), swapped = written.Eval(wo, wi);
      cell_band[m] = static_cast<int8_t>(theta_max < 25.0 ? 0 : theta_max < 50.0 ? 1 : 2);
      for (int c = 0; c < 3; ++c) {
        cell_errors[m][c] = t[c] > 0.0 ? std::abs(g[c] - t[c]) / t[c] : -1.0;
        cell_reciprocity[m][c] =
            t[c] > 0.0 && g[c] + swapped[c] > 0.0 ? 2.0 * std::abs(g[c] - swapped[c]) / (g[c] + swapped[c]) : -1.0;
      }
    }
  });
  TableReadBack back;
  double worst = -1.0;
  for (size_t m = 0; m < checked; ++m) {
    for (int c = 0; c < 3 && cell_band[m] >= 0; ++c) {
      if (cell_errors[m][c] <= worst) continue;
      worst = cell_errors[m][c];
      const size_t flat = cells[m * stride];
      Eigen::Vector3d wi, wo;
      FromHalfDiff(MerlCellCentre(int(flat / (size_t(kMerlThetaD) * kMerlPhiD)), int(flat / kMerlPhiD % kMerlThetaD),
                                  int(flat % kMerlPhiD)),
                   &wi, &wo);
      const double t = table.Cell(flat)[c];
      back.worst_ratio = written.Eval(wi, wo)[c] / t;
      const double dphi = std::abs(std::remainder(std::atan2(wo.y(), wo.x()) - std::atan2(wi.y(), wi.x()), 2 * M_PI));
      back.worst_at_deg = Eigen::Vector3d(std::acos(wi.z()), std::acos(wo.z()), dphi) * (180.0 / M_PI);
    }
  }
  back.band_errors.assign(3, {});
  back.band_reciprocity.assign(3, {});
  for (size_t m = 0; m < checked; ++m) {
    if (cell_band[m] < 0) continue;
    for (int c = 0; c < 3; ++c) {
      if (cell_errors[m][c] >= 0.0) {
        back.errors.push_back(cell_errors[m][c]);
        back.band_errors[cell_band[m]].push_back(cell_errors[m][c]);
      }
      if (cell_reciprocity[m][c] >= 0.0) {
        back.reciprocity.push_back(cell_reciprocity[m][c]);
        back.band_reciprocity[cell_band[m]].push_back(cell_reciprocity[m][c]);
      }
    }
  }
  // Each list sorted once, then read at its quantiles.
  std::vector<std::vector<double>*> lists = {&back.errors, &back.reciprocity};
  for (int b = 0; b < 3; ++b) lists.insert(lists.end(), {&back.band_errors[b], &back.band_reciprocity[b]});
  tbb::parallel_for(size_t(0), lists.size(), [&](size_t list) { std::sort(lists[list]->begin(), lists[list]->end()); });
  return back;
}

// NAME.bsdf from the regression (measured and interpolated nodes) and, where it has no data, the chosen
// fit (else the regression's extrapolation, else 0), said in the file's description and the summary;
// then read back as the readers do and compared with the table over its measured cells.
void ExportBsdf(const LocalRegression& regression, const ReconstructOptions& options, const BrdfModel* chosen,
                const MerlTable& table, const std::vector<uint8_t>& domain, const std::string& name,
                const std::string& samples_file, const std::string& tmp, ReconstructResult* result,
                nlohmann::json* timings) {
  Timer timer;
  DomainCounts classes;
  uint64_t filled_model = 0, filled_extrapolated = 0, zero = 0;
  std::vector<float> measured_errors;  // the measured nodes' standard errors, largest channel
  const BrdfBatch source = [&](const std::vector<Eigen::Vector3d>& wi, const std::vector<Eigen::Vector3d>& wo,
                               std::vector<Eigen::Vector3d>* f) {
    const size_t n = wi.size();
    std::vector<Eigen::Vector3d> uvw(n);
    std::vector<double> theta_d(n);
    for (size_t i = 0; i < n; ++i) {
      HalfDiffAngles angles;
      ToHalfDiff(wi[i], wo[i], &angles);
      theta_d[i] = angles.theta_d;
      uvw[i] = RegressionCoordinates(angles);
    }
    // A node beyond the samples' theta_d range is unmeasured whatever its estimate; with a fit to fill
    // it the estimate is not needed, so it is not computed (as in the tabulation): such nodes (near
    // retro-reflection, at grazing angles) are the regression's most expensive, its support grown.
    const double margin = options.tabulate.domain.theta_d_margin_deg * M_PI / 180.0;
    std::vector<size_t> evaluated;
    std::vector<Eigen::Vector3d> evaluated_uvw;
    for (size_t i = 0; i < n; ++i) {
      const bool beyond =
          theta_d[i] < regression.theta_d_min() - margin || theta_d[i] > regression.theta_d_max() + margin;
      if (beyond && chosen) continue;
      evaluated.push_back(i);
      evaluated_uvw.push_back(uvw[i]);
    }
    const std::vector<Estimate> some = regression.EvaluateMany(evaluated_uvw, nullptr);
    std::vector<Estimate> estimates(n);  // default: unsupported, so unmeasured
    for (size_t k = 0; k < evaluated.size(); ++k) estimates[evaluated[k]] = some[k];
    f->assign(n, Eigen::Vector3d::Zero());
    for (size_t i = 0; i < n; ++i) {
      const Estimate& e = estimates[i];
      DomainClass c = ClassifyEstimate(e, theta_d[i], regression, options.tabulate.domain);
      if (e.effective_samples < options.tabulate.min_effective_samples) c = DomainClass::kUnmeasured;
      classes.Add(c);
      if (c == DomainClass::kMeasured) measured_errors.push_back(e.standard_error.maxCoeff());
      if (c != DomainClass::kUnmeasured) {
        (*f)[i] = e.value;
      } else if (chosen) {
        (*f)[i] = chosen->Eval(wi[i], wo[i]);
        ++filled_model;
      } else if (e.status != EstimateStatus::kUnsupported) {
        (*f)[i] = e.value;
        ++filled_extrapolated;
      } else {
        ++zero;
      }
    }
  };
  // The description is written after the tables are built (it names what was filled), so the tables
  // are built first with a placeholder and the text replaced.
  TensorFile file = BuildRglBsdf(source, "", options.bsdf_export);
  const uint64_t nodes = classes.measured + classes.interpolated + classes.unmeasured;
  file["description"] = TextField(BsdfDescription(name, samples_file, classes, chosen, filled_extrapolated, zero, measured_errors));
  const std::string file_name = name + ".bsdf";
  WriteTensorFile(tmp + "/" + file_name, file);
  const double build_s = timer.ElapsedSeconds();

  // Read back as a reader does and compare with the table over its measured cells (theta <= 80).
  const RglBsdf written(tmp + "/" + file_name);
  const TableReadBack back = CompareWithTable(written, table, domain);
  auto quantile = [](const std::vector<double>& sorted, double q) {
    if (sorted.empty()) return 0.0;
    return sorted[std::min(sorted.size() - 1, size_t(q * double(sorted.size())))];
  };
  auto figures = [&](const std::vector<double>& sorted) -> nlohmann::json {
    return {{"median", quantile(sorted, 0.5)},
            {"p95", quantile(sorted, 0.95)},
            {"p99", quantile(sorted, 0.99)},
            {"max", sorted.empty() ? 0.0 : sorted.back()},
            {"values", sorted.size()}};
  };
  nlohmann::json bands = nlohmann::json::object(), reciprocity_bands = nlohmann::json::object();
  const char* band_names[] = {"0-25", "25-50", "50-80"};
  for (int b = 0; b < 3; ++b) {
    bands[band_names[b]] = figures(back.band_errors[b]);
    reciprocity_bands[band_names[b]] = figures(back.band_reciprocity[b]);
  }
  const std::vector<double>& errors = back.errors;
  result->bsdf_written = true;
  result->bsdf_median_error = quantile(errors, 0.5);
  result->bsdf_p95_error = quantile(errors, 0.95);
  result->bsdf_p99_error = quantile(errors, 0.99);
  result->bsdf_max_error = errors.empty() ? 0.0 : errors.back();
  result->bsdf_p99_reciprocity = quantile(back.reciprocity, 0.99);
  (*timings)["bsdf_s"] = timer.ElapsedSeconds();
  const BsdfExportOptions& o = options.bsdf_export;
  result->summary["bsdf"] = {
      {"file", file_name},
      {"format", "RGL tensor file (Dupuy and Jakob 2018): Mitsuba 3 / pbrt-v4 measured, brdf-loader"},
      {"theta_i_count", o.theta_i_count},
      {"max_theta_i_deg", o.max_theta_i_deg},
      {"rgb_size", o.rgb_size},
      {"vndf_size", o.vndf_size},
      {"ndf_size", o.ndf_size},
      {"nodes",
       {{"measured", classes.measured},
        {"interpolated", classes.interpolated},
        {"unmeasured", classes.unmeasured},
        {"filled_with_model", filled_model},
        {"filled_with_extrapolation", filled_extrapolated},
        {"zero", zero},
        {"fill_model", chosen ? chosen->ModelName() : ""}}},
      {"error_against_table",
       {{"domain", "measured cells (domain.npy 2), theta_i, theta_e <= 80 deg, every channel"},
        {"median", result->bsdf_median_error},
        {"p95", result->bsdf_p95_error},
        {"p99", result->bsdf_p99_error},
        {"max", result->bsdf_max_error},
        {"values", errors.size()},
        {"worst", {{"file_over_table", back.worst_ratio},
                   {"theta_i_deg", back.worst_at_deg[0]},
                   {"theta_e_deg", back.worst_at_deg[1]},
                   {"delta_phi_deg", back.worst_at_deg[2]}}},
        {"by_theta_max_deg", bands}}},
      {"reciprocity",
       {{"domain", "the same cells: |f(wi, wo) - f(wo, wi)| / their mean, as read back from the file"},
        {"median", quantile(back.reciprocity, 0.5)},
        {"p99", result->bsdf_p99_reciprocity},
        {"max", back.reciprocity.empty() ? 0.0 : back.reciprocity.back()},
        {"values", back.reciprocity.size()},
        {"by_theta_max_deg", reciprocity_bands}}},
      {"uncertainty",
       "the format has no uncertainty field: the measured nodes' standard errors are stated in the file's "
       "description; per cell in uncertainty.npy"},
      {"build_s", build_s}};
  Log(1, "wrote " + file_name + " (RGL .bsdf; " + std::to_string(classes.unmeasured) + " of " + std::to_string(nodes) +
             " nodes unmeasured" +
             (classes.unmeasured ? chosen ? ", filled with the " + chosen->ModelName() + " fit" : ", extrapolated or 0"
                                 : std::string()) +
             "); read back against the table's measured cells: " + BandFigures(result->bsdf_median_error,
             result->bsdf_p99_error, result->bsdf_max_error) + "; the file's reciprocity p99 " +
             Percent(result->bsdf_p99_reciprocity));
}

nlohmann::json RegressionJson(const ReconstructOptions& options, const LocalRegressionOptions& r,
                              const LocalRegression& regression) {
  return {{"degree", r.degree},
          {"bandwidth", options.select_bandwidth ? BandwidthCriterionName(options.selection.criterion) : "given"},
          {"radius_h_deg", r.radius_h_deg},
          {"radius_d_deg", r.radius_d_deg},
          {"fold_reciprocity", r.fold_reciprocity},
          {"fold_bilateral", r.fold_bilateral},
          {"log_space", r.log_space},
          {"bin_fraction_h", r.bin_fraction_h},
          {"bin_fraction_d", r.bin_fraction_d},
          {"samples_used", regression.size()},
          {"points", regression.points()},
          {"samples_skipped", regression.skipped_samples()}};
}

// The samples' colour space and colour-chart correction, as their sidecar states them (the derenderer's
// "colour_space" and "colour"), carried into summary.json and brdf.json; "unknown" without a sidecar.
void CopySampleColour(const std::string& samples_file, nlohmann::json* summary) {
  (*summary)["colour_space"] = "unknown (the samples have no sidecar)";
  if (samples_file.empty() || !std::filesystem::is_regular_file(SidecarPath(samples_file))) return;
  const nlohmann::json sidecar = ReadJsonFile(SidecarPath(samples_file));
  if (sidecar.contains("colour_space")) (*summary)["colour_space"] = sidecar["colour_space"];
  if (sidecar.contains("colour")) (*summary)["colour"] = sidecar["colour"];
  if (sidecar.contains("intensity_scale")) (*summary)["intensity_scale"] = sidecar["intensity_scale"];
}

// The stage after its inputs are read; `total` started before they were.
ReconstructResult Run(const std::vector<BrdfSample>& samples, const ReconstructOptions& options,
                      const StageInputs& inputs, const std::string& out_dir, const std::string& samples_file,
                      const Timer& total) {
  if (samples.empty()) ThrowError(samples_file.empty() ? "samples" : samples_file, "holds no samples");
  ReconstructResult result;
  result.samples = samples.size();
  result.summary = {
      {"format", "ibrdf-reconstruction"}, {"version", 1}, {"samples_file", samples_file}, {"samples", samples.size()}};
  CopySampleColour(samples_file, &result.summary);
  AtomicDirectory dir(out_dir, options.overwrite);
  const std::string tmp = dir.temporary_path();
  nlohmann::json timings;
  result.regression = options.regression;
  if (options.select_bandwidth) {
    const BandwidthSelection selection = SelectBandwidth(samples, options.regression, options.selection);
    Log(1, "bandwidth criterion curve (" + std::string(BandwidthCriterionName(selection.criterion)) + "):\n" +
               selection.CurveTable());
    Log(1, selection.BriefReport());
    if (!selection.success) ThrowError("--bandwidth", "no candidate kernel gave a finite criterion");
    result.summary["bandwidth_selection"] = ToJson(selection);
    timings["bandwidth_selection_s"] = selection.seconds;
    result.regression = selection.selected;
  }
  Timer timer;
  const LocalRegression regression(samples, result.regression);
  timings["build_s"] = timer.ElapsedSeconds();
  result.samples_used = regression.size();
  result.points = regression.points();
  // The fits run beside the evaluation and tabulation (both TBB-parallel: the two share the cores),
  // unless --fill model needs the chosen fit first. They write into their own result and timings,
  // merged after.
  std::unique_ptr<BrdfModel> chosen;
  ReconstructResult fitted;
  nlohmann::json fit_timings;
  const bool fits = options.fits && !options.eval_only;
  const bool fill_with_model = options.tabulate.fill == FillMode::kModel;
  const std::string name = MaterialName(options, samples_file);
  // Read before the fits start: they run beside the tabulation, which writes into result.summary.
  const nlohmann::json space = result.summary.value("colour_space", nlohmann::json());
  const std::string colour_space = space.is_string() ? space.get<std::string>() : space.is_null() ? "" : space.dump();
  const bool relative_scale = result.summary.value("intensity_scale", "absolute") == "relative";
  if (relative_scale) Log(1, "relative scale: the samples' lights are known up to one common intensity");
  auto fit = [&] {
    chosen = FitModels(samples, options.fit, name, colour_space, relative_scale, tmp, &fitted, &fit_timings);
  };
  tbb::task_group fitting;
  if (fits && fill_with_model) {
    fit();
    if (!chosen) {
      ThrowError("--fill model", "no plausible fit to fill the unmeasured cells with: " +
                                     fitted.summary["fits"]["rejected"].dump() +
                                     " (--fill extrapolate or none leaves them to the regression)");
    }
  }
  if (fits && !fill_with_model) fitting.run(fit);
  MerlTable table;
  std::vector<uint8_t> domain;
  TableFiles table_files;
  try {
    const BrdfModel* fill_model = fill_with_model ? chosen.get() : nullptr;
    if (!inputs.eval_wi.empty()) {
      EvaluatePoints(regression, inputs, options, fill_model, tmp, &result.summary, &timings);
      result.eval_points = inputs.eval_wi.size();
    }
    result.summary["regression"] = RegressionJson(options, result.regression, regression);
    if (!options.eval_only) {
      Tabulate(regression, options, fill_model, &result, &timings, &table, &domain, &table_files);
    }
  } catch (...) {
    fitting.wait();  // rethrows a fit's error, if any; otherwise the tabulation's below
    throw;
  }
  fitting.wait();
  if (fitted.fitted) {
    result.summary["fits"] = fitted.summary["fits"];
    result.fitted = true;
    result.lafortune_rel_rms = fitted.lafortune_rel_rms;
    result.ggx_rel_rms = fitted.ggx_rel_rms;
    result.chosen_model = fitted.chosen_model;
    timings["fits_s"] = fit_timings["fits_s"];
  }
  if (!options.eval_only) {
    // The table's files and the score against the truth beside the .bsdf export (the score into its own
    // summary object, merged after).
    nlohmann::json score;
    tbb::task_group scoring;
    double write_s = 0.0;
    scoring.run([&] { write_s = WriteTable(table, domain, table_files, tmp); });
    if (inputs.truth) {
      scoring.run([&] {
        const Timer score_timer;
        Score(table, domain, table_files.uncertainty, *inputs.truth, options, &score, &result);
        score["score_s"] = score_timer.ElapsedSeconds();
      });
    }
    try {
      if (options.bsdf) {
        ExportBsdf(regression, options, chosen.get(), table, domain, name, samples_file, tmp, &result, &timings);
      }
    } catch (...) {
      scoring.wait();
      throw;
    }
    scoring.wait();
    timings["write_s"] = write_s;
    if (inputs.truth) {
      timings["score_s"] = score["score_s"];
      score.erase("score_s");
      for (auto& [key, value] : score.items()) result.summary[key] = value;
    }
  }
  result.total_s = total.ElapsedSeconds();
  timings["total_s"] = result.total_s;
  result.summary["timings_s"] = timings;
  WriteJsonFile(tmp + "/summary.json", result.summary);
  dir.Commit();
  Log(1, "reconstruction written to " + out_dir);
  result.success = true;
  return result;
}

}  // namespace

bool ReconstructOptions::Check(std::string* why) const {
  std::string inner;
  const auto fail = [&](const char* group) {
    if (why) *why = std::string(group) + ": " + inner;
    return false;
  };
  if (!regression.Check(&inner)) return fail("regression");
  if (!selection.Check(&inner)) return fail("selection");
  if (!tabulate.Check(&inner)) return fail("tabulate");
  if (!fit.Check(&inner)) return fail("fit");
  if (!bsdf_export.Check(&inner)) return fail("bsdf_export");
  IBRDF_CHECK_OPTION(!eval_only || !eval_file.empty());
  // --fill model fills with the chosen fit, so the fits must run.
  IBRDF_CHECK_OPTION(tabulate.fill != FillMode::kModel || (fits && !eval_only));
  return true;
}

std::string ReconstructResult::BriefReport() const {
  std::ostringstream out;
  out << "reconstruct: " << (success ? "" : "FAILED, ") << samples << " samples (" << samples_used << " used, "
      << points << " points)";
  if (eval_points) out << ", " << eval_points << " points evaluated";
  if (tabulated) {
    out << ", cells " << cells_measured << " measured, " << cells_interpolated << " interpolated, " << cells_unmeasured
        << " unmeasured";
    if (cells_filled) out << " (" << cells_filled << " filled)";
  }
  if (fitted) {
    out << ", fits rel. RMS Lafortune " << lafortune_rel_rms << " GGX " << ggx_rel_rms << " (chosen " << chosen_model
        << ")";
  }
  if (bsdf_written) out << ", .bsdf vs table median " << 100 * bsdf_median_error << " %";
  if (scored) out << ", against the truth " << error_against_truth.Brief();
  out << ", " << total_s << " s";
  return out.str();
}

ReconstructResult Reconstruct(const std::vector<BrdfSample>& samples, const ReconstructOptions& options,
                              const std::string& out_dir, const std::string& samples_file) {
  const StageInputs inputs = LoadInputs(options);
  const Timer total;
  return Run(samples, options, inputs, out_dir, samples_file, total);
}

ReconstructResult ReconstructFile(const std::string& samples_file, const ReconstructOptions& options,
                                  const std::string& out_dir) {
  const StageInputs inputs = LoadInputs(options);
  const Timer total;
  const std::vector<BrdfSample> samples = ReadSamples(samples_file);
  return Run(samples, options, inputs, out_dir, samples_file, total);
}

}  // namespace ibrdf

namespace ibrdf {

ReconstructResult EvaluateMaterial(const std::string& material_file, const ReconstructOptions& options,
                                   const std::string& out_dir) {
  const Timer total;
  if (options.eval_file.empty()) ThrowError("--material", "needs --eval POINTS.npy");
  StageInputs inputs;
  LoadEvalPoints(options.eval_file, &inputs);
  const std::unique_ptr<BrdfModel> material = LoadTruth(material_file);
  ReconstructResult result;
  AtomicDirectory dir(out_dir, options.overwrite);
  const std::string tmp = dir.temporary_path();
  const Timer timer;
  const size_t n = inputs.eval_wi.size();
  std::vector<double> values(3 * n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const Eigen::Vector3d f = material->Eval(inputs.eval_wi[i], inputs.eval_wo[i]);
      for (int c = 0; c < 3; ++c) values[3 * i + c] = f[c];
    }
  });
  const double eval_s = timer.ElapsedSeconds();
  uint64_t no_data = 0;
  if (const auto* merl = dynamic_cast<const MerlBrdf*>(material.get())) {
    // The MERL reader's "no data": -1 where the looked-up cell has none.
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d f = merl->table().Lookup(inputs.eval_wi[i], inputs.eval_wo[i]);
      if ((f.array() < 0.0).any() && inputs.eval_wi[i].z() > 0.0 && inputs.eval_wo[i].z() > 0.0) {
        for (int c = 0; c < 3; ++c) values[3 * i + c] = -1.0;
        ++no_data;
      }
    }
  }
  WriteNpyArray(tmp + "/eval.npy", values, {n, 3});
  result.eval_points = n;
  result.total_s = total.ElapsedSeconds();
  result.summary = {{"format", "ibrdf-reconstruction"},
                    {"version", 1},
                    {"material", material_file},
                    {"model", material->ModelName()},
                    {"eval", {{"points", n}, {"file", options.eval_file}, {"no_data", no_data}}},
                    {"timings_s", {{"eval_s", eval_s}, {"total_s", result.total_s}}}};
  WriteJsonFile(tmp + "/summary.json", result.summary);
  dir.Commit();
  Log(1, "evaluated " + material->ModelName() + " material " + material_file + " at " + std::to_string(n) +
             " points in " + std::to_string(eval_s) + " s" +
             (no_data ? " (" + std::to_string(no_data) + " on cells without data: -1)" : ""));
  result.success = true;
  return result;
}

}  // namespace ibrdf
