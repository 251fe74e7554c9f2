#include "workflow/measurement.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "core/file_util.h"
#include "core/session.h"
#include "core/truth_file.h"
#include "workflow/stamp.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string Absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

// A stage that applies, without an action yet (Planner::Execute gives it the launcher's).
Stage MakeStage(std::string name, std::vector<std::string> arguments, std::vector<std::string> inputs,
                std::vector<std::string> outputs) {
  Stage stage;
  stage.name = std::move(name);
  stage.arguments = std::move(arguments);
  stage.inputs = std::move(inputs);
  stage.outputs = std::move(outputs);
  return stage;
}

// The plan's state as the stages run: each reads the session the previous one wrote.
class Planner {
 public:
  Planner(const MeasurementOptions& options, const StageLauncher& launch, WorkflowRun* run)
      : options_(options), launch_(launch), run_(run) {}

  std::string At(const std::string& name) const { return run_->Path(name); }

  // Executes `stage`; one without an action runs its arguments through the launcher.
  void Execute(Stage stage) { run_->Execute(WithAction(std::move(stage))); }

  // Executes `stages` at the same time (WorkflowRun::ExecuteTogether); all but `live` send their output
  // to DIR/logs/<name>.log, printed when they end.
  void ExecuteTogether(std::vector<Stage> stages, const std::string& live) {
    for (Stage& stage : stages) {
      if (stage.name == live) continue;
      stage.output_log = At("logs/" + stage.name + ".log");
    }
    for (Stage& stage : stages) stage = WithAction(std::move(stage));
    run_->ExecuteTogether(std::move(stages));
  }

  // The session at `path`; absent only when the stage that writes it was left out by --stop-after.
  std::optional<Session> SessionAt(const std::string& path) const {
    if (run_->stopped() && !fs::exists(path)) return std::nullopt;
    return Session::Load(path);
  }

  // `stage` with its action: as given, or its arguments through the launcher (into its output_log).
  Stage WithAction(Stage stage) const {
    if (!stage.action) {
      stage.action = [launch = launch_, name = stage.name, arguments = stage.arguments, log = stage.output_log] {
        // The log's folder appears only when a stage really runs (never in a dry run).
        if (!log.empty()) fs::create_directories(fs::path(log).parent_path());
        return launch(name, arguments, log);
      };
    }
    return stage;
  }

  void Synth(const Recipe& recipe);
  void Scan();
  void Response();
  void Align();
  void Lights();
  void Colour();
  void Derender();
  void SampleStages();  // check, compare, reconstruct, report

  std::string manifest_path;  // the input session (synth's for a recipe)
  std::string current;        // the manifest the next stage reads
  std::string truth_path;     // truth.json beside the input session, if any
  // The truth is a material map (synth --material-map): no single material to compare the samples with.
  bool truth_spatially_varying = false;
  std::string material_name;  // the fitted materials' name: the recipe's, else the input session's folder

 private:
  const MeasurementOptions& options_;
  StageLauncher launch_;
  WorkflowRun* run_;
};

void Planner::Synth(const Recipe& recipe) {
  Stage synth = recipe.material_map.empty()
                    ? MakeStage("synth", {"synth", "--material", recipe.material}, {recipe.path, recipe.material},
                                {At("synth/session.json"), At("synth/truth.json")})
                    : MakeStage("synth", {"synth", "--material-map", recipe.material_map},
                                {recipe.path, recipe.material_map}, {At("synth/session.json"), At("synth/truth.json")});
  synth.inputs.insert(synth.inputs.end(), recipe.map_materials.begin(), recipe.map_materials.end());
  synth.arguments.insert(synth.arguments.end(), recipe.synth_args.begin(), recipe.synth_args.end());
  synth.arguments.insert(synth.arguments.end(), {"--out", At("synth"), "--overwrite"});
  Execute(synth);
  manifest_path = At("synth/session.json");
}

// A mesh sample with raw scans: `ibrdf scan --session` merges them into DIR/scan/mesh.ply, and
// DIR/scan/session.json is the session with that mesh (every path absolute, no scan_inputs).
void Planner::Scan() {
  const std::optional<Session> session = SessionAt(manifest_path);
  Stage scan =
      MakeStage("scan", {}, {manifest_path}, {At("scan/mesh.ply"), At("scan/mesh.ply.json"), At("scan/session.json")});
  if (!session || !IsMeshSample(session->sample.kind)) {
    scan.not_applicable = "the sample is analytic, not a scanned mesh";
  } else if (session->sample.scan_inputs.empty()) {
    scan.not_applicable = "the session's mesh sample has no scan_inputs";
  } else {
    for (const ScanInputSpec& input : session->sample.scan_inputs) {
      scan.inputs.push_back(session->AbsolutePath(input.file));
    }
    fs::create_directories(At("scan"));
    scan.arguments = {"scan", "--session", manifest_path, "--out", At("scan/mesh.ply"), "--overwrite"};
    scan.arguments.insert(scan.arguments.end(), options_.scan_args.begin(), options_.scan_args.end());
    Session merged = *session;
    merged.sample.mesh_file = At("scan/mesh.ply");
    merged.sample.scan_inputs.clear();
    merged.MarkApplied(SessionStage::kScan);
    scan.action = [launch = launch_, arguments = scan.arguments, merged, folder = At("scan")] {
      const int code = launch("scan", arguments, "");
      if (code == 0) merged.SaveRebased(folder, Session::PathStyle::kAbsolute);
      return code;
    };
  }
  const bool applies = scan.not_applicable.empty();
  Execute(scan);
  if (applies) current = At("scan/session.json");
}

// Sessions whose camera response is unknown (radiometry.response kind "unknown"): `ibrdf response`
// measures it from the exposure brackets into DIR/response/session.json. It runs before align, as
// every later stage that reads a photo's values linearly (the light fits, the white reference, the
// derenderer) needs the curve; a session whose response is stated, measured or not, is used as it is.
void Planner::Response() {
  const std::optional<Session> session = SessionAt(current);
  Stage response = MakeStage("response", {"response", current, "--out", At("response"), "--overwrite"}, {current},
                             {At("response/session.json"), At("response/response.json")});
  if (session) {
    for (const std::string& file : session->InputFiles()) response.inputs.push_back(file);
  }
  response.arguments.insert(response.arguments.end(), options_.response_args.begin(), options_.response_args.end());
  if (!session || session->radiometry.response.kind != Response::Kind::kUnknown) {
    if (options_.stop_after != "response") return;
    response.not_applicable = "the session states its camera response (radiometry.response)";
  }
  const bool applies = response.not_applicable.empty();
  Execute(response);
  if (applies) current = At("response/session.json");
}

// Sessions with coded targets; otherwise every photo needs its pose.
void Planner::Align() {
  const std::optional<Session> session = SessionAt(current);
  Stage align = MakeStage("align", {"align", current, "--out", At("align"), "--overwrite"}, {current},
                          {At("align/session.json"), At("align/alignment.json")});
  if (session) {
    for (const std::string& file : session->InputFiles()) align.inputs.push_back(file);
  }
  align.arguments.insert(align.arguments.end(), options_.align_args.begin(), options_.align_args.end());
  if (session && session->Applied(SessionStage::kAlign)) {
    // A session `ibrdf align` wrote: resumed as it is, never aligned twice (its name would grow).
    align.not_applicable = "the session was aligned already (stages_applied); its poses are used as they are";
  } else if (!session || !session->targets) {
    align.not_applicable = "the session has no targets; its photos' poses are used as given";
    for (size_t i = 0; session && i < session->photos.size(); ++i) {
      if (!session->photos[i].camera_from_world) {
        ThrowError(current + ": /photos/" + std::to_string(i) + "/camera_from_world",
                   "missing, and the session has no targets block from which `ibrdf align` could find it");
      }
    }
  }
  const bool applies = align.not_applicable.empty();
  Execute(align);
  if (applies) current = At("align/session.json");
}

// Sessions with a white reference: `ibrdf lights white` measures the lights' intensities into
// DIR/lights/session.json (the white reference consumed), which the later stages read. Sessions without
// one have no such stage in their plan (unless --stop-after names it), so their runs are as before.
void Planner::Lights() {
  const std::optional<Session> session = SessionAt(current);
  Stage lights = MakeStage("lights", {"lights", "white", current, "--out", At("lights"), "--overwrite"}, {current},
                           {At("lights/session.json"), At("lights/white-reference.json")});
  lights.arguments.insert(lights.arguments.end(), options_.lights_args.begin(), options_.lights_args.end());
  if (session) {
    for (const std::string& file : session->InputFiles()) lights.inputs.push_back(file);
  }
  if (!session || !session->calibration || !session->calibration->white_reference) {
    if (options_.stop_after != "lights") return;
    lights.not_applicable = "the session has no white reference";
  }
  const bool applies = lights.not_applicable.empty();
  Execute(lights);
  if (applies) current = At("lights/session.json");
}

// Sessions with a colour chart: `ibrdf colour` fits its matrix into DIR/colour/session.json, which the
// derenderer applies.
void Planner::Colour() {
  const std::optional<Session> session = SessionAt(current);
  Stage colour = MakeStage("colour", {"colour", current, "--out", At("colour"), "--overwrite"}, {current},
                           {At("colour/session.json"), At("colour/colour.json")});
  if (session) {
    for (const std::string& file : session->InputFiles()) colour.inputs.push_back(file);
  }
  colour.arguments.insert(colour.arguments.end(), options_.colour_args.begin(), options_.colour_args.end());
  if (!session || !session->colour_chart) {
    colour.not_applicable = "the session has no colour_chart";
  } else if (session->colour_chart->matrix) {
    colour.not_applicable =
        "the session's colour chart is fitted already (colour_chart.matrix); it is applied as it is";
  }
  const bool applies = colour.not_applicable.empty();
  Execute(colour);
  if (applies) current = At("colour/session.json");
}

void Planner::Derender() {
  const std::optional<Session> session = SessionAt(current);
  Stage derender = MakeStage("derender", {"derender", current, "--out", At("samples.npy"), "--overwrite"}, {current},
                             {At("samples.npy"), At("samples.npy.json")});
  if (options_.pixel_stride != 1) {
    derender.arguments.push_back("--stride");
    derender.arguments.push_back(std::to_string(options_.pixel_stride));
  }
  if (session) {
    for (const std::string& file : session->InputFiles()) derender.inputs.push_back(file);
  }
  derender.arguments.insert(derender.arguments.end(), options_.derender_args.begin(), options_.derender_args.end());
  Execute(derender);
}

void Planner::SampleStages() {
  const std::vector<std::string> samples_in = {At("samples.npy"), At("samples.npy.json")};
  Stage check = MakeStage("check", {"check", At("samples.npy"), "--out", At("consistency.json"), "--overwrite"},
                          samples_in, {At("consistency.json")});
  if (options_.check_regression) check.arguments.push_back("--regression");
  check.arguments.insert(check.arguments.end(), options_.check_args.begin(), options_.check_args.end());

  Stage compare = MakeStage("compare", {}, samples_in, {At("truth-comparison.json")});
  if (truth_path.empty()) {
    compare.not_applicable = "no truth.json beside the session (not synthetic)";
  } else if (truth_spatially_varying) {
    compare.not_applicable = kSpatiallyVaryingTruth;
  } else {
    compare.arguments = {"compare", At("samples.npy"),           "--truth",    truth_path,
                         "--out",   At("truth-comparison.json"), "--overwrite"};
    compare.inputs.push_back(truth_path);
  }

  Stage reconstruct =
      MakeStage("reconstruct", {"reconstruct", At("samples.npy"), "--out", At("reconstruction"), "--overwrite"},
                samples_in, {At("reconstruction/summary.json"), At("reconstruction/brdf.binary")});
  if (!truth_path.empty() && !truth_spatially_varying) {
    reconstruct.arguments.insert(reconstruct.arguments.end(), {"--truth", truth_path});
    reconstruct.inputs.push_back(truth_path);
  }
  auto pass = [&](const char* flag, double value, double unset) {
    if (value == unset) return;
    std::ostringstream text;
    text << value;
    reconstruct.arguments.insert(reconstruct.arguments.end(), {flag, text.str()});
  };
  pass("--degree", options_.degree, -1);
  pass("--radius-h-deg", options_.radius_h_deg, -1.0);
  pass("--radius-d-deg", options_.radius_d_deg, -1.0);
  if (!options_.fits) reconstruct.arguments.push_back("--no-fits");
  // The input's name, not that of the stage folder (align/, lights/, colour/) whose session the samples came from.
  const std::vector<std::string>& extra = options_.reconstruct_args;
  if (!material_name.empty() && std::find(extra.begin(), extra.end(), "--name") == extra.end()) {
    reconstruct.arguments.insert(reconstruct.arguments.end(), {"--name", material_name});
  }
  reconstruct.arguments.insert(reconstruct.arguments.end(), extra.begin(), extra.end());
  // The three only read the samples (and the truth): with concurrent_sample_stages, reconstruct (the
  // longest, its progress shown live) runs beside check and compare, filling the cores its serial parts
  // leave idle. The stage order, outputs and stamps are those of the sequential run.
  if (options_.concurrent_sample_stages) {
    ExecuteTogether({check, compare, reconstruct}, "reconstruct");
  } else {
    Execute(check);
    Execute(compare);
    Execute(reconstruct);
  }

  // Whether the object is one material: its surface cells' samples against the reconstruction.
  Stage uniformity = MakeStage("uniformity",
                               {"uniformity", At("samples.npy"), "--brdf", At("reconstruction/brdf.binary"), "--session",
                                current, "--out", At("uniformity"), "--overwrite"},
                               {At("samples.npy"), At("samples.npy.json"), At("reconstruction/brdf.binary"), current},
                               {At("uniformity/uniformity.json"), At("uniformity/map.png")});
  // Asked to measure each group, a sample that is not one material is what the materials stage
  // handles: the failed check is accepted, and so recorded.
  if (options_.spatial) uniformity.arguments.insert(uniformity.arguments.end(), {"--accept", "uniformity.cells"});
  uniformity.arguments.insert(uniformity.arguments.end(), options_.uniformity_args.begin(),
                              options_.uniformity_args.end());
  Execute(uniformity);

  // Each group of cells as a material of its own, only when asked (a uniform object keeps one BRDF and
  // its cost).
  Stage materials = MakeStage("materials",
                              {"materials", At("samples.npy"), "--uniformity", At("uniformity/uniformity.json"),
                               "--session", current, "--out", At("materials"), "--overwrite"},
                              {At("samples.npy"), At("samples.npy.json"), At("uniformity/uniformity.json"), current},
                              {At("materials/materials.json")});
  if (!options_.spatial) {
    materials.not_applicable = "not asked (run --spatial measures each group of the uniformity check's cells)";
  } else {
    if (!truth_path.empty()) {
      materials.arguments.insert(materials.arguments.end(), {"--truth", truth_path});
      materials.inputs.push_back(truth_path);
    }
    if (!options_.fits) materials.arguments.push_back("--no-fits");
    if (!material_name.empty()) materials.arguments.insert(materials.arguments.end(), {"--name", material_name});
    materials.arguments.insert(materials.arguments.end(), options_.materials_args.begin(),
                               options_.materials_args.end());
  }
  Execute(materials);

  Stage report = MakeStage("report", {"report", run_->run_dir(), "--out", At("report"), "--overwrite"}, {},
                           {At("report/index.html")});
  report.arguments.insert(report.arguments.end(), options_.report_args.begin(), options_.report_args.end());
  if (!options_.report) {
    report.not_applicable = "--no-report";
  } else {
    report.inputs = {At("samples.npy"), At("samples.npy.json"), At("consistency.json"),
                     At("reconstruction/summary.json"), At("reconstruction/brdf.binary"),
                     At("uniformity/uniformity.json")};
    if (options_.spatial) report.inputs.push_back(At("materials/materials.json"));
    if (!truth_path.empty() && !truth_spatially_varying) report.inputs.push_back(At("truth-comparison.json"));
    for (const Stage& stage : run_->stages()) {
      if (run_->outcome(stage.name).status != StageStatus::kNotApplicable) {
        report.inputs.push_back(StampPath(run_->run_dir(), stage.name));
      }
    }
  }
  Execute(report);
}

}  // namespace

const std::vector<std::string>& MeasurementStageNames() {
  static const std::vector<std::string> kStages = {"synth",    "scan",  "response", "align",       "lights", "colour",
                                                   "derender", "check", "compare",  "reconstruct", "uniformity",
                                                   "materials", "report"};
  return kStages;
}

bool MeasurementOptions::Check(std::string* why) const {
  if (pixel_stride < 1) {
    *why = "--stride must be at least 1";
    return false;
  }
  if (degree != -1 && (degree < 0 || degree > 2)) {
    *why = "--degree must be 0, 1 or 2";
    return false;
  }
  if ((radius_h_deg != -1.0 && !(radius_h_deg > 0.0)) || (radius_d_deg != -1.0 && !(radius_d_deg > 0.0))) {
    *why = "kernel radii must be positive";
    return false;
  }
  const std::vector<std::string>& stages = MeasurementStageNames();
  if (!stop_after.empty() && std::find(stages.begin(), stages.end(), stop_after) == stages.end()) {
    *why = "--stop-after: unknown stage \"" + stop_after +
           "\" (synth, scan, response, align, lights, colour, derender, check, compare, reconstruct, uniformity, materials, report)";
    return false;
  }
  return true;
}

MeasurementInput OpenMeasurementInput(const std::string& input, const std::string& out) {
  if (!fs::exists(input)) {
    ThrowError(input, "does not exist (expected a session folder, session.json or a recipe folder)");
  }
  MeasurementInput result;
  if (fs::is_directory(input) && fs::exists(fs::path(input) / "recipe.json")) {
    result.recipe = ReadRecipe((fs::path(input) / "recipe.json").string());
  } else if (fs::path(input).filename() == "recipe.json") {
    result.recipe = ReadRecipe(input);
  } else {
    const std::string manifest = fs::is_directory(input) ? (fs::path(input) / "session.json").string() : input;
    if (!fs::exists(manifest)) ThrowError(input, "holds neither session.json nor recipe.json");
    result.manifest_path = Absolute(manifest);
    Session::Load(result.manifest_path);
  }
  const std::string run_dir = Absolute(out);
  if (!result.manifest_path.empty() && SameFile(run_dir, fs::path(result.manifest_path).parent_path().string())) {
    ThrowError(out, "is the session's folder; the run writes into a folder of its own");
  }
  if (fs::exists(run_dir) && !fs::is_directory(run_dir)) ThrowError(out, "exists and is not a folder");
  return result;
}

std::string RunMeasurement(const MeasurementInput& input, const MeasurementOptions& options,
                           const StageLauncher& launch, WorkflowRun* run) {
  Planner plan(options, launch, run);
  plan.manifest_path = input.manifest_path;
  if (input.recipe) plan.Synth(*input.recipe);
  const fs::path session_dir = fs::path(plan.manifest_path).parent_path();
  plan.material_name = input.recipe ? input.recipe->name : session_dir.filename().string();
  if (fs::exists(session_dir / "truth.json")) plan.truth_path = (session_dir / "truth.json").string();
  // A recipe's map says so before synth ran (a dry run); a session's truth.json says so itself.
  plan.truth_spatially_varying = (input.recipe && !input.recipe->material_map.empty()) ||
                                 (!plan.truth_path.empty() && IsSpatiallyVaryingTruth(plan.truth_path));
  plan.current = plan.manifest_path;
  plan.Scan();
  plan.Response();
  plan.Align();
  plan.Lights();
  plan.Colour();
  plan.Derender();
  plan.SampleStages();
  return plan.truth_path;
}

}  // namespace ibrdf
