#include "workflow/run_summary.h"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/truth_file.h"
#include "workflow/stage_json.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// samples.npy.json: derender's counts.
void AddSamples(const fs::path& dir, nlohmann::json* summary) {
  const std::optional<StageJson> side = StageJson::ReadIfExists((dir / "samples.npy.json").string());
  if (!side) return;
  side->Object("/counts");
  // Each rejection count checked here, where a bad one is blamed on this file, not on summary.json.
  const nlohmann::json rejected = side->ObjectOr("/counts/rejected", nlohmann::json::object());
  for (const auto& [reason, count] : rejected.items()) side->Count("/counts/rejected/" + reason);
  (*summary)["session"] = side->String("/session", "");
  (*summary)["session_name"] = side->String("/session_name", "");
  (*summary)["intensity_scale"] = side->String("/intensity_scale", "absolute");
  (*summary)["samples"] = {{"file", (dir / "samples.npy").string()},
                           {"photos", side->Count("/counts/photos", 0)},
                           {"pixels_examined", side->Count("/counts/pixels_examined", 0)},
                           {"accepted", side->Count("/counts/accepted", 0)},
                           {"rejected", rejected}};
  // Exposure advice: the sentences of derender's warnings, when it had any.
  nlohmann::json warnings = nlohmann::json::array();
  const nlohmann::json list = side->ValueOr("/exposure/warnings", nlohmann::json::array());
  if (list.is_array()) {
    for (const nlohmann::json& w : list) {
      if (w.is_object() && w.contains("message") && w["message"].is_string()) warnings.push_back(w["message"]);
    }
  }
  (*summary)["samples"]["exposure_warnings"] = warnings;
}

// consistency.json: `ibrdf check`'s figures (null where a figure is not valid): the median over bins
// (`reciprocity`, `bilateral_symmetry`), the 95th percentile, per channel and the bins compared. A
// consistency.json of the previous release names bilateral symmetry "isotropy"; it is read under that
// name. The summary writes "isotropy*" copies of the bilateral-symmetry keys for one release.
void AddConsistency(const fs::path& dir, nlohmann::json* summary) {
  const std::optional<StageJson> c = StageJson::ReadIfExists((dir / "consistency.json").string());
  if (!c) return;
  nlohmann::json out;
  for (const std::string figure : {"reciprocity", "bilateral_symmetry"}) {
    std::string at = "/" + figure;
    if (!c->Has(at) && figure == "bilateral_symmetry") at = "/isotropy";
    if (!c->Has(at)) continue;
    const bool valid = c->Boolean(at + "/valid", false);
    out[figure] = valid ? c->Figure(at + "/overall_rel_error") : nlohmann::json();
    out[figure + "_p95"] = valid ? c->FigureOr(at + "/p95_rel_error", nlohmann::json()) : nlohmann::json();
    out[figure + "_per_channel"] = c->FigureOr(at + "/per_channel_rel_error", nlohmann::json());
    out[figure + "_bins_compared"] = c->Count(at + "/bins_compared", 0);
  }
  if (out.contains("bilateral_symmetry")) {
    for (const char* suffix : {"", "_per_channel", "_bins_compared"}) {
      out[std::string("isotropy") + suffix] = out[std::string("bilateral_symmetry") + suffix];
    }
    out["aliases"] = {{"isotropy", "bilateral_symmetry (deprecated name, removed in the next release)"}};
  }
  if (c->Has("/regression")) out["regression"] = c->Value("/regression");
  (*summary)["consistency"] = out;
}

// reconstruction/summary.json: the table's and the fits' figures as reconstruct wrote them.
void AddReconstruction(const fs::path& dir, nlohmann::json* summary) {
  const std::optional<StageJson> r = StageJson::ReadIfExists((dir / "reconstruction" / "summary.json").string());
  if (!r) return;
  (*summary)["reconstruction"] = {{"folder", (dir / "reconstruction").string()},
                                  {"merl", (dir / "reconstruction" / "brdf.binary").string()},
                                  {"table", r->ValueOr("/table", nlohmann::json())},
                                  {"fits", r->ValueOr("/fits", nlohmann::json())}};
}

// truth-comparison.json and the reconstruction's error against the truth (synthetic sessions).
void AddTruth(const fs::path& dir, const std::string& truth_path, nlohmann::json* summary) {
  if (truth_path.empty()) return;
  nlohmann::json truth = {{"file", truth_path}};
  if (fs::exists(truth_path) && IsSpatiallyVaryingTruth(truth_path)) {
    // No figures against one material: compare did not run and reconstruct was given no truth.
    truth["spatially_varying"] = true;
    truth["comparison"] = kSpatiallyVaryingTruth;
    (*summary)["truth"] = truth;
    return;
  }
  if (const std::optional<StageJson> t = StageJson::ReadIfExists((dir / "truth-comparison.json").string())) {
    truth["samples_median_rel_error"] = t->Figure("/overall/median_rel_error");
    truth["samples_p95_rel_error"] = t->Figure("/overall/p95_rel_error");
    truth["samples_mean_signed_rel_error"] = t->Figure("/overall/mean_signed_rel_error");
    truth["samples_compared"] = t->Count("/overall/count");
  }
  const std::optional<StageJson> r = StageJson::ReadIfExists((dir / "reconstruction" / "summary.json").string());
  if (r && r->Has("/error_against_truth")) {
    truth["brdf_rel_rmse"] = r->Figure("/error_against_truth/rel_rms_error");
    truth["brdf_rel_rmse_all"] = r->Figure("/error_against_truth/rel_rms_error_all");
    truth["brdf_cells_scored"] = r->Count("/error_against_truth/cells_scored");
    truth["brdf_coverage"] = r->Figure("/error_against_truth/coverage");
  }
  (*summary)["truth"] = truth;
}

// With --spatial: the groups measured as materials (materials/materials.json): per group its samples,
// the folder of its reconstruction and, with a truth, its material and error; the labels' score; the
// cells' weights over the groups (the fraction no combination fits; with a truth, the weights' error).
void AddMaterials(const fs::path& dir, nlohmann::json* summary) {
  const std::optional<StageJson> m = StageJson::ReadIfExists((dir / "materials" / "materials.json").string());
  if (!m) return;
  nlohmann::json groups = nlohmann::json::array();
  for (const nlohmann::json& g : m->ValueOr("/groups", nlohmann::json::array())) {
    nlohmann::json entry = {{"samples", g.value("samples", 0)}, {"reconstructed", g.value("reconstructed", false)}};
    if (g.contains("folder")) entry["folder"] = "materials/" + g["folder"].get<std::string>();
    if (g.contains("truth_name")) entry["truth_name"] = g["truth_name"];
    if (g.contains("error_against_truth")) {
      entry["brdf_rel_rmse_all"] = g["error_against_truth"].value("rel_rms_error_all", nlohmann::json());
    }
    groups.push_back(entry);
  }
  nlohmann::json materials = {{"groups", groups}};
  const nlohmann::json labels = m->ValueOr("/labels", nlohmann::json());
  if (labels.is_object()) materials["labels_right_fraction"] = labels.value("right_fraction", nlohmann::json());
  const nlohmann::json weights = m->ValueOr("/weights", nlohmann::json());
  if (weights.is_object()) {
    nlohmann::json w = {{"bases", weights.value("bases", nlohmann::json::array())},
                        {"cells_fitted", weights.value("cells_fitted", 0)},
                        {"not_fitting_fraction", weights.value("not_fitting_fraction", nlohmann::json())},
                        {"median_rel_rms", weights.value("median_rel_rms", nlohmann::json())}};
    if (weights.contains("truth")) w["truth"] = weights["truth"];
    materials["weights"] = w;
  }
  const nlohmann::json prediction = m->ValueOr("/prediction", nlohmann::json());
  if (prediction.is_object()) {
    materials["prediction"] = {
        {"photo", prediction.value("photo", 0)},
        {"held_out", prediction.value("held_out", false)},
        {"model_median_abs_rel_error", prediction.value("model_median_abs_rel_error_all", nlohmann::json())},
        {"single_brdf_median_abs_rel_error", prediction.value("single_brdf_median_abs_rel_error_all", nlohmann::json())},
        {"truth_median_abs_rel_error", prediction.value("truth_median_abs_rel_error_all", nlohmann::json())},
        {"image", prediction.value("image", nlohmann::json())}};
  }
  for (const char* file : {"mesh", "pbrt"}) {
    const nlohmann::json part = m->ValueOr(std::string("/") + file, nlohmann::json());
    if (part.is_object()) materials[file] = part;
  }
  (*summary)["materials"] = materials;
}

// The calibration stages', the uniformity check's and the materials stage's verdicts
// (response/response.json, align/alignment.json, lights/white-reference.json, colour/colour.json,
// uniformity/uniformity.json and materials/materials.json "verdicts", core/verdict.h), each with its stage, and every stage's warnings in one list: the
// verdicts that are not ok (an accepted failure included, marked so), align's own warnings and
// derender's exposure advice.
void AddVerdicts(const fs::path& dir, nlohmann::json* summary) {
  nlohmann::json verdicts = nlohmann::json::array(), warnings = nlohmann::json::array();
  for (const auto& [stage, file] : {std::pair<std::string, std::string>{"response", "response/response.json"},
                                    std::pair<std::string, std::string>{"align", "align/alignment.json"},
                                    std::pair<std::string, std::string>{"lights", "lights/white-reference.json"},
                                    std::pair<std::string, std::string>{"colour", "colour/colour.json"},
                                    std::pair<std::string, std::string>{"uniformity", "uniformity/uniformity.json"},
                                    std::pair<std::string, std::string>{"materials", "materials/materials.json"}}) {
    const std::optional<StageJson> stage_json = StageJson::ReadIfExists((dir / file).string());
    if (!stage_json) continue;
    const nlohmann::json list = stage_json->ValueOr("/verdicts", nlohmann::json::array());
    for (size_t i = 0; list.is_array() && i < list.size(); ++i) {
      const std::string at = "/verdicts/" + std::to_string(i);
      nlohmann::json v = {{"stage", stage},
                          {"check", stage_json->String(at + "/check")},
                          {"verdict", stage_json->String(at + "/verdict")},
                          {"measured", stage_json->String(at + "/measured", "")},
                          {"bound", stage_json->String(at + "/bound", "")},
                          {"remedy", stage_json->String(at + "/remedy", "")},
                          {"accepted", stage_json->Boolean(at + "/accepted", false)}};
      if (v["verdict"] != "ok") {
        warnings.push_back(stage + ": " + v["check"].get<std::string>() + ": " + v["verdict"].get<std::string>() +
                           (v["accepted"].get<bool>() ? " (accepted by the user)" : "") + ": " +
                           v["measured"].get<std::string>() + "; bound: " + v["bound"].get<std::string>());
      }
      verdicts.push_back(v);
    }
    const nlohmann::json own = stage_json->ValueOr("/warnings", nlohmann::json::array());
    for (const nlohmann::json& w : own) {
      if (w.is_string()) warnings.push_back(stage + ": " + w.get<std::string>());
    }
  }
  if (summary->contains("samples")) {
    for (const nlohmann::json& w : (*summary)["samples"]["exposure_warnings"])
      warnings.push_back("derender: " + w.get<std::string>());
  }
  (*summary)["verdicts"] = verdicts;
  (*summary)["warnings"] = warnings;
}

// "1.23 %", or "n/a" for a null (NaN) or absent figure.
std::string Percent(const nlohmann::json& value) {
  if (!value.is_number()) return "n/a";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f %%", 100.0 * value.get<double>());
  return buffer;
}

// "1.00 %, 2.00 %, 3.00 %" per channel, or "n/a" when not an array.
std::string PercentPerChannel(const nlohmann::json& value) {
  if (!value.is_array()) return "n/a";
  std::string text;
  for (const nlohmann::json& x : value) text += (text.empty() ? "" : ", ") + Percent(x);
  return text;
}

}  // namespace

nlohmann::json BuildRunSummary(const WorkflowRun& run, const std::string& input, const std::string& truth_path,
                               double wall_s) {
  const fs::path dir(run.run_dir());
  nlohmann::json summary = {{"format", "ibrdf-run"}, {"version", 1}, {"input", input}, {"run_dir", run.run_dir()}};
  nlohmann::json stages = nlohmann::json::object(), timings = nlohmann::json::object();
  double stage_sum = 0.0;
  for (const Stage& stage : run.stages()) {
    const StageOutcome& outcome = run.outcome(stage.name);
    stages[stage.name] = {{"status", StageStatusName(outcome.status)}, {"reason", outcome.reason}};
    if (outcome.status != StageStatus::kNotApplicable) {
      timings[stage.name] = outcome.seconds;
      stage_sum += outcome.seconds;
    }
  }
  timings["stages_total"] = stage_sum;
  timings["this_invocation"] = wall_s;
  summary["stages"] = stages;
  summary["timings_s"] = timings;
  AddSamples(dir, &summary);
  AddConsistency(dir, &summary);
  AddReconstruction(dir, &summary);
  AddTruth(dir, truth_path, &summary);
  AddVerdicts(dir, &summary);
  AddMaterials(dir, &summary);
  const std::string report = (dir / "report" / "index.html").string();
  if (fs::exists(report)) summary["report"] = report;
  return summary;
}

std::vector<std::string> RunHeadline(const nlohmann::json& summary_json) {
  const StageJson summary(summary_json, "summary.json");
  std::vector<std::string> lines;
  const nlohmann::json verdicts = summary.ValueOr("/verdicts", nlohmann::json::array());
  for (const nlohmann::json& v : verdicts) {
    if (!v.is_object() || v.value("verdict", "") == "ok") continue;
    lines.push_back(std::string("verdict: ") + v.value("stage", "") + " " + v.value("check", "") + ": " +
                    v.value("verdict", "") + (v.value("accepted", false) ? " (accepted by the user)" : "") + ": " +
                    v.value("measured", "") + "; bound: " + v.value("bound", ""));
  }
  if (summary.ValueOr("/intensity_scale", "absolute") == "relative") {
    lines.push_back("relative scale: the lights' intensities are known up to one common scale; so is every BRDF value");
  }
  if (summary.Has("/samples")) {
    std::string rejected;
    for (const auto& [reason, count] : summary.Object("/samples/rejected").items()) {
      const uint64_t n = summary.Count("/samples/rejected/" + reason);
      if (n > 0) rejected += (rejected.empty() ? "" : ", ") + reason + " " + std::to_string(n);
    }
    lines.push_back("samples: " + std::to_string(summary.Count("/samples/accepted")) +
                    " accepted; rejected: " + (rejected.empty() ? "none" : rejected));
    const nlohmann::json warnings = summary.ValueOr("/samples/exposure_warnings", nlohmann::json::array());
    if (warnings.is_array()) {
      for (const nlohmann::json& w : warnings) {
        if (w.is_string()) lines.push_back("warning: " + w.get<std::string>());
      }
    }
  }
  if (summary.Has("/consistency")) {
    lines.push_back("consistency: reciprocity " + Percent(summary.ValueOr("/consistency/reciprocity", nullptr)) +
                    ", bilateral symmetry " + Percent(summary.ValueOr("/consistency/bilateral_symmetry", nullptr)) +
                    " (medians over bins)");
  }
  if (summary.ValueOr("/truth/spatially_varying", false) == true) {
    lines.push_back(std::string("against the truth: ") + kSpatiallyVaryingTruth +
                    " (truth.json's material_map gives it point by point)");
  } else if (summary.Has("/truth")) {
    lines.push_back("against the truth: samples' median relative error (R, G, B) " +
                    PercentPerChannel(summary.ValueOr("/truth/samples_median_rel_error", nullptr)) +
                    "; reconstruction relative RMS " +
                    PercentPerChannel(summary.ValueOr("/truth/brdf_rel_rmse", nullptr)));
  }
  return lines;
}

}  // namespace ibrdf
