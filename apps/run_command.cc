// ibrdf run: the whole workflow (synth for a recipe, scan, align, derender, check, compare, reconstruct,
// report) into one run folder, each stage a child process of this same binary, skipped when its outputs
// are newer than its inputs and its command line is unchanged. Decisions: docs/workflow.md.
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "apps/commands.h"
#include "core/subprocess.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/session.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// Options of the whole run; the stage options are passed on to the children unchanged.
struct RunOptions {
  int pixel_stride = 1;           // derender --stride
  int degree = -1;                // reconstruct --degree (-1: its default)
  double radius_h_deg = -1.0;     // reconstruct --radius-h-deg (-1: its default)
  double radius_d_deg = -1.0;     // reconstruct --radius-d-deg (-1: its default)
  bool fits = true;               // reconstruct's Lafortune and GGX fits
  bool check_regression = false;  // check --regression (slower: three held-out fits)
  bool report = true;             // the HTML report
  bool force = false;             // re-run every stage
  std::string stop_after;         // the last stage to run ("": all of them)

  bool Check(std::string* why) const {
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
    static const std::vector<std::string> kStages = {"synth", "scan",    "align",       "derender",
                                                     "check", "compare", "reconstruct", "report"};
    if (!stop_after.empty() && std::find(kStages.begin(), kStages.end(), stop_after) == kStages.end()) {
      *why = "--stop-after: unknown stage \"" + stop_after +
             "\" (synth, scan, align, derender, check, compare, reconstruct, report)";
      return false;
    }
    return true;
  }
};

// One stage of the plan. A stage with a non-empty `not_applicable` is skipped with that reason.
struct Stage {
  std::string name;
  std::vector<std::string> args;     // the child's arguments after `ibrdf [verbosity]`
  std::vector<std::string> inputs;   // files whose change re-runs the stage
  std::vector<std::string> outputs;  // files the stage must leave behind
  std::string not_applicable;
};

// What happened to a stage in this invocation.
struct StageOutcome {
  std::string status;  // "ran", "skipped" (up to date), "not_applicable"
  std::string reason;
  double seconds = 0.0;  // this run's wall time, or the recorded time of the run that made the outputs
};

std::string Absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

std::string SelfExecutable() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  IBRDF_CHECK(!error) << "cannot read /proc/self/exe: " << error.message();
  return self.string();
}

// size and modification time (ns) of a file; {-1, -1} if absent.
std::pair<int64_t, int64_t> Fingerprint(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return {-1, -1};
  return {int64_t(st.st_size), int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

std::string StampPath(const std::string& run_dir, const std::string& stage) {
  return (fs::path(run_dir) / "stamps" / (stage + ".json")).string();
}

nlohmann::json InputFingerprints(const Stage& stage) {
  nlohmann::json inputs = nlohmann::json::array();
  for (const std::string& input : stage.inputs) {
    const auto [size, mtime] = Fingerprint(input);
    inputs.push_back({{"path", input}, {"size", size}, {"mtime_ns", mtime}});
  }
  return inputs;
}

// Empty when the stage's outputs are up to date; otherwise why it must run.
std::string WhyStale(const std::string& run_dir, const Stage& stage, const std::string& version) {
  const std::string stamp_path = StampPath(run_dir, stage.name);
  if (!fs::exists(stamp_path)) return "no record of a completed run";
  nlohmann::json stamp;
  try {
    stamp = ReadJsonFile(stamp_path);
  } catch (const Error&) {
    return "its record is unreadable";
  }
  if (stamp.value("version", "") != version) return "ibrdf version changed";
  if (stamp.value("args", nlohmann::json()) != nlohmann::json(stage.args)) return "options changed";
  if (stamp.value("inputs", nlohmann::json()) != InputFingerprints(stage)) return "an input changed";
  int64_t newest_input = 0;
  for (const std::string& input : stage.inputs) newest_input = std::max(newest_input, Fingerprint(input).second);
  for (const std::string& output : stage.outputs) {
    const int64_t mtime = Fingerprint(output).second;
    if (mtime < 0) return output + " is missing";
    if (mtime < newest_input) return output + " is older than an input";
  }
  return "";
}

// Leftovers of an interrupted stage: hidden ".NAME.tmp-PID-N" files and folders (core/file_util.h)
// whose writer is gone. Only inside the run folder and its direct subfolders.
void RemoveStaleTemporaries(const std::string& run_dir) {
  std::vector<fs::path> folders = {run_dir};
  for (const auto& entry : fs::directory_iterator(run_dir)) {
    if (entry.is_directory() && entry.path().filename().string()[0] != '.') folders.push_back(entry.path());
  }
  for (const fs::path& folder : folders) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      const size_t at = name.rfind(".tmp-");
      if (name.empty() || name[0] != '.' || at == std::string::npos) continue;
      const int pid = std::atoi(name.c_str() + at + 5);
      if (pid > 0 && (::kill(pid, 0) == 0 || errno != ESRCH)) continue;  // its writer still runs
      std::error_code ignored;
      fs::remove_all(entry.path(), ignored);
      Log(1, "removed the leftover of an interrupted stage: " + entry.path().string());
    }
  }
}

// A manifest's photo files, resolved against its folder (raw JSON: the child stages validate it).
std::vector<std::string> PhotoFiles(const nlohmann::json& manifest, const std::string& manifest_path) {
  std::vector<std::string> files;
  const fs::path folder = fs::path(manifest_path).parent_path();
  if (!manifest.contains("photos") || !manifest["photos"].is_array()) return files;
  for (const nlohmann::json& photo : manifest["photos"]) {
    if (photo.is_object() && photo.contains("file") && photo["file"].is_string()) {
      files.push_back(ResolvePath(folder.string(), photo["file"].get<std::string>()));
    }
  }
  return files;
}

// Every string of the manifest that names a file relative to its folder (photos, the mesh, scans,
// calibration images ...) made absolute, so the manifest can be written elsewhere.
void AbsolutizePaths(nlohmann::json* value, const std::string& folder, const std::string& key) {
  if (value->is_object()) {
    for (auto it = value->begin(); it != value->end(); ++it) AbsolutizePaths(&it.value(), folder, it.key());
  } else if (value->is_array()) {
    for (nlohmann::json& element : *value) AbsolutizePaths(&element, folder, key);
  } else if (value->is_string()) {
    const std::string text = value->get<std::string>();
    if (text.empty() || fs::path(text).is_absolute()) return;
    const fs::path resolved = fs::path(folder) / text;
    if (key == "file" || key == "scan_inputs" || fs::is_regular_file(resolved)) *value = Absolute(resolved.string());
  }
}

// The recipe of a synthetic experiment (samples/<name>/recipe.json): the material and synth's options.
struct Recipe {
  std::string path;
  std::string name;
  std::string material;  // absolute
  std::vector<std::string> synth_args;
};

Recipe ReadRecipe(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  JsonObject root(json, path);
  if (root.String("format") != "ibrdf-recipe") ThrowError(root.Where("format"), "expected \"ibrdf-recipe\"");
  if (root.Integer("version") != 1) ThrowError(root.Where("version"), "expected 1");
  Recipe recipe;
  recipe.path = path;
  recipe.name = root.String("name");
  root.String("description", "");
  root.String("paper", "");
  recipe.material = Absolute(ResolvePath(fs::path(path).parent_path().string(), root.String("material")));
  RequireFile(recipe.material, root.Where("material"));
  const nlohmann::json& synth = root.Raw("synth");
  if (!synth.is_array()) ThrowError(root.Where("synth"), "expected an array of synth arguments (strings)");
  for (const nlohmann::json& arg : synth) {
    if (!arg.is_string()) ThrowError(root.Where("synth"), "expected strings, got " + JsonTypeName(arg));
    const std::string text = arg.get<std::string>();
    if (text == "--out" || text == "--material" || text == "--overwrite") {
      ThrowError(root.Where("synth"), text + " is set by `ibrdf run`, not by the recipe");
    }
    recipe.synth_args.push_back(text);
  }
  root.Finish();
  return recipe;
}

std::string FormatSeconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f s", s);
  return buffer;
}

// DIR/summary.json from the stages' own outputs (docs/workflow.md lists the fields).
nlohmann::json BuildSummary(const std::string& run_dir, const std::string& session_path,
                            const std::vector<Stage>& stages, const std::map<std::string, StageOutcome>& outcomes,
                            const std::string& truth_path, double wall_s) {
  const fs::path dir(run_dir);
  nlohmann::json summary = {{"format", "ibrdf-run"}, {"version", 1}, {"input", session_path}, {"run_dir", run_dir}};
  nlohmann::json stage_json = nlohmann::json::object(), timings = nlohmann::json::object();
  double stage_sum = 0.0;
  for (const Stage& stage : stages) {
    const StageOutcome& outcome = outcomes.at(stage.name);
    stage_json[stage.name] = {{"status", outcome.status}, {"reason", outcome.reason}};
    if (outcome.status != "not_applicable") {
      timings[stage.name] = outcome.seconds;
      stage_sum += outcome.seconds;
    }
  }
  timings["stages_total"] = stage_sum;
  timings["this_invocation"] = wall_s;
  summary["stages"] = stage_json;
  summary["timings_s"] = timings;

  const std::string sidecar = (dir / "samples.npy.json").string();
  if (fs::exists(sidecar)) {
    const nlohmann::json side = ReadJsonFile(sidecar);
    const nlohmann::json& counts = side.at("counts");
    summary["session"] = side.value("session", "");
    summary["session_name"] = side.value("session_name", "");
    summary["samples"] = {{"file", (dir / "samples.npy").string()},
                          {"photos", counts.value("photos", 0)},
                          {"pixels_examined", counts.value("pixels_examined", 0)},
                          {"accepted", counts.value("accepted", 0)},
                          {"rejected", counts.value("rejected", nlohmann::json::object())}};
  }
  const std::string consistency = (dir / "consistency.json").string();
  if (fs::exists(consistency)) {
    const nlohmann::json c = ReadJsonFile(consistency);
    nlohmann::json out;
    for (const char* figure : {"reciprocity", "isotropy"}) {
      if (!c.contains(figure)) continue;
      out[figure] = c[figure].value("valid", false) ? c[figure]["overall_rel_error"] : nlohmann::json();
      out[std::string(figure) + "_per_channel"] = c[figure].value("per_channel_rel_error", nlohmann::json());
      out[std::string(figure) + "_bins_compared"] = c[figure].value("bins_compared", 0);
    }
    if (c.contains("regression")) out["regression"] = c["regression"];
    summary["consistency"] = out;
  }
  const std::string reconstruction = (dir / "reconstruction" / "summary.json").string();
  if (fs::exists(reconstruction)) {
    const nlohmann::json r = ReadJsonFile(reconstruction);
    summary["reconstruction"] = {{"folder", (dir / "reconstruction").string()},
                                 {"merl", (dir / "reconstruction" / "brdf.binary").string()},
                                 {"table", r.value("table", nlohmann::json())},
                                 {"fits", r.value("fits", nlohmann::json())}};
  }
  if (!truth_path.empty()) {
    nlohmann::json truth = {{"file", truth_path}};
    const std::string comparison = (dir / "truth-comparison.json").string();
    if (fs::exists(comparison)) {
      const nlohmann::json t = ReadJsonFile(comparison);
      truth["samples_median_rel_error"] = t["overall"]["median_rel_error"];
      truth["samples_p95_rel_error"] = t["overall"]["p95_rel_error"];
      truth["samples_mean_signed_rel_error"] = t["overall"]["mean_signed_rel_error"];
      truth["samples_compared"] = t["overall"]["count"];
    }
    if (fs::exists(reconstruction)) {
      const nlohmann::json r = ReadJsonFile(reconstruction);
      if (r.contains("error_against_truth")) {
        truth["brdf_rel_rmse"] = r["error_against_truth"]["rel_rms_error"];
        truth["brdf_rel_rmse_all"] = r["error_against_truth"]["rel_rms_error_all"];
        truth["brdf_cells_scored"] = r["error_against_truth"]["cells_scored"];
        truth["brdf_coverage"] = r["error_against_truth"]["coverage"];
      }
    }
    summary["truth"] = truth;
  }
  const std::string report = (dir / "report" / "index.html").string();
  if (fs::exists(report)) summary["report"] = report;
  return summary;
}

void PrintHeadline(const nlohmann::json& summary) {
  auto percent = [](const nlohmann::json& v) {
    if (!v.is_array()) return std::string("n/a");
    std::string text;
    for (const nlohmann::json& x : v) {
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%s%.2f %%", text.empty() ? "" : ", ", 100.0 * x.get<double>());
      text += buffer;
    }
    return text;
  };
  if (summary.contains("samples")) {
    std::string rejected;
    for (auto it = summary["samples"]["rejected"].begin(); it != summary["samples"]["rejected"].end(); ++it) {
      if (it.value().get<uint64_t>() == 0) continue;
      rejected += (rejected.empty() ? "" : ", ") + it.key() + " " + std::to_string(it.value().get<uint64_t>());
    }
    Log(1, "samples: " + std::to_string(summary["samples"]["accepted"].get<uint64_t>()) +
               " accepted; rejected: " + (rejected.empty() ? "none" : rejected));
  }
  if (summary.contains("consistency")) {
    const nlohmann::json& c = summary["consistency"];
    auto one = [](const nlohmann::json& v) {
      if (!v.is_number()) return std::string("n/a");
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%.2f %%", 100.0 * v.get<double>());
      return std::string(buffer);
    };
    Log(1, "consistency: reciprocity " + one(c.value("reciprocity", nlohmann::json())) + ", bilateral symmetry " +
               one(c.value("isotropy", nlohmann::json())));
  }
  if (summary.contains("truth")) {
    const nlohmann::json& t = summary["truth"];
    Log(1, "against the truth: samples' median relative error (R, G, B) " +
               percent(t.value("samples_median_rel_error", nlohmann::json())) + "; reconstruction relative RMS " +
               percent(t.value("brdf_rel_rmse", nlohmann::json())));
  }
}

void AddRunCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "run",
      "The whole workflow into one folder: (synth, for a recipe) -> scan -> align -> derender -> check ->\n"
      "compare (synthetic sessions) -> reconstruct -> report, each stage a child `ibrdf` process. A stage is\n"
      "skipped when its outputs are newer than its inputs and its options are unchanged (DIR/stamps/), so an\n"
      "interrupted run resumes where it stopped. Writes DIR/summary.json (docs/workflow.md).");
  struct Args {
    std::string input, out;
    RunOptions options;
  };
  auto args = std::make_shared<Args>();
  RunOptions& o = args->options;
  command
      ->add_option("session", args->input,
                   "Session folder or session.json; or a recipe folder (samples/<name>, with recipe.json)")
      ->required();
  command->add_option("--out", args->out, "Run folder (created; an existing one is resumed)")->required();
  command->add_option("--stride", o.pixel_stride, "derender: every n-th pixel in x and y")->capture_default_str();
  command->add_option("--degree", o.degree, "reconstruct: local polynomial degree (default: reconstruct's)");
  command->add_option("--radius-h-deg", o.radius_h_deg,
                      "reconstruct: kernel radius along the sheets (default: reconstruct's)");
  command->add_option("--radius-d-deg", o.radius_d_deg,
                      "reconstruct: kernel radius across the sheets (default: reconstruct's)");
  command->add_flag("!--no-fits", o.fits, "reconstruct: skip the Lafortune and GGX fits");
  command->add_flag("--check-regression", o.check_regression, "check: also the regression checks (held-out photos)");
  command->add_flag("!--no-report", o.report, "Skip the HTML report");
  command->add_flag("--force", o.force, "Re-run every stage, up to date or not");
  command->add_option("--stop-after", o.stop_after,
                      "Stop after this stage (synth, scan, align, derender, check, compare,\n"
                      "reconstruct, report); later stages are left as they are");
  command->callback([args] {
    Timer wall;
    std::string why;
    if (!args->options.Check(&why)) ThrowError("ibrdf run", why);
    const RunOptions& options = args->options;
    const std::string version = "ibrdf 0.1.0";

    // The input: a recipe folder, or a session (validated here, so a bad one is one clear line).
    std::string input = args->input;
    if (!fs::exists(input))
      ThrowError(input, "does not exist (expected a session folder, session.json or a recipe folder)");
    std::optional<Recipe> recipe;
    std::string manifest_path;
    if (fs::is_directory(input) && fs::exists(fs::path(input) / "recipe.json")) {
      recipe = ReadRecipe((fs::path(input) / "recipe.json").string());
    } else if (fs::path(input).filename() == "recipe.json") {
      recipe = ReadRecipe(input);
    } else {
      manifest_path = fs::is_directory(input) ? (fs::path(input) / "session.json").string() : input;
      if (!fs::exists(manifest_path)) ThrowError(input, "holds neither session.json nor recipe.json");
      manifest_path = Absolute(manifest_path);
      Session::Load(manifest_path);
    }
    const std::string run_dir = Absolute(args->out);
    if (!manifest_path.empty() && SameFile(run_dir, fs::path(manifest_path).parent_path().string())) {
      ThrowError(args->out, "is the session's folder; the run writes into a folder of its own");
    }
    if (fs::exists(run_dir) && !fs::is_directory(run_dir)) ThrowError(args->out, "exists and is not a folder");
    fs::create_directories(fs::path(run_dir) / "stamps");
    RemoveStaleTemporaries(run_dir);
    const fs::path dir(run_dir);
    auto at = [&](const std::string& name) { return (dir / name).string(); };

    std::vector<std::string> child_prefix = {SelfExecutable()};
    if (Verbosity() == 0) child_prefix.push_back("--silent");
    if (Verbosity() == 1) child_prefix.push_back("-q");
    child_prefix.push_back("--threads");
    child_prefix.push_back(
        std::to_string(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));

    std::vector<Stage> stages;
    std::map<std::string, StageOutcome> outcomes;
    std::string truth_path;

    // Runs one stage (or skips it) and records its outcome; the plan of later stages depends on the
    // files earlier ones wrote, so stages are planned and run one by one.
    std::string stopped;
    // A manifest a later stage reads; absent only when an earlier stage was left out by --stop-after.
    auto manifest_of = [&](const std::string& path) {
      return fs::exists(path) || stopped.empty() ? ReadJsonFile(path) : nlohmann::json::object();
    };
    auto execute = [&](Stage stage, const std::function<void()>& after = nullptr) {
      if (!stopped.empty()) stage.not_applicable = stopped;
      if (stage.name == options.stop_after) stopped = "--stop-after " + options.stop_after;
      stages.push_back(stage);
      StageOutcome& outcome = outcomes[stage.name];
      const int number = int(stages.size());
      if (!stage.not_applicable.empty()) {
        outcome = {"not_applicable", stage.not_applicable, 0.0};
        Log(1,
            "== run " + std::to_string(number) + ": " + stage.name + ": not applicable (" + stage.not_applicable + ")");
        return;
      }
      const std::string stale = options.force ? "--force" : WhyStale(run_dir, stage, version);
      if (stale.empty()) {
        const nlohmann::json stamp = ReadJsonFile(StampPath(run_dir, stage.name));
        outcome = {"skipped", "up to date", stamp.value("seconds", 0.0)};
        Log(1, "== run " + std::to_string(number) + ": " + stage.name + ": up to date, skipped (took " +
                   FormatSeconds(outcome.seconds) + " when it ran)");
        return;
      }
      Log(1, "== run " + std::to_string(number) + ": " + stage.name + " (" + stale + ")");
      std::error_code ignored;
      fs::remove(StampPath(run_dir, stage.name), ignored);
      std::vector<std::string> argv = child_prefix;
      argv.insert(argv.end(), stage.args.begin(), stage.args.end());
      Timer timer;
      const int code = RunSubprocess(argv, {"", {}, stage.name});
      if (code != 0) {
        ThrowError("ibrdf run", "stage " + stage.name + " failed (exit " + std::to_string(code) +
                                    (code > 128 ? ", killed by signal " + std::to_string(code - 128) : "") +
                                    "); fix the cause and run again to resume from it");
      }
      if (after) after();
      outcome = {"ran", stale, timer.ElapsedSeconds()};
      const nlohmann::json stamp = {{"version", version},       {"stage", stage.name},
                                    {"args", stage.args},       {"inputs", InputFingerprints(stage)},
                                    {"outputs", stage.outputs}, {"seconds", outcome.seconds}};
      WriteJsonFile(StampPath(run_dir, stage.name), stamp);
      Log(1, "-- run: " + stage.name + ": " + FormatSeconds(outcome.seconds));
    };

    // synth (recipes only).
    if (recipe) {
      Stage synth{"synth",
                  {"synth", "--material", recipe->material},
                  {recipe->path, recipe->material},
                  {at("synth/session.json"), at("synth/truth.json")},
                  ""};
      synth.args.insert(synth.args.end(), recipe->synth_args.begin(), recipe->synth_args.end());
      for (const char* tail : {"--out", "", "--overwrite"}) synth.args.push_back(tail);
      synth.args[synth.args.size() - 2] = at("synth");
      execute(synth);
      manifest_path = at("synth/session.json");
      if (stopped.empty() || fs::exists(manifest_path)) Session::Load(manifest_path);
    }
    const std::string session_dir = fs::path(manifest_path).parent_path().string();
    if (fs::exists(fs::path(session_dir) / "truth.json")) truth_path = (fs::path(session_dir) / "truth.json").string();
    const nlohmann::json original = manifest_of(manifest_path);
    std::string current = manifest_path;  // the manifest the next stage reads

    // scan: a mesh sample with raw scans merges them into the run folder's mesh.
    {
      Stage scan{
          "scan", {}, {manifest_path}, {at("scan/mesh.ply"), at("scan/mesh.ply.json"), at("scan/session.json")}, ""};
      const nlohmann::json* sample = original.contains("sample") ? &original["sample"] : nullptr;
      if (!sample || sample->value("kind", "") != "mesh") {
        scan.not_applicable = "the sample is analytic, not a scanned mesh";
      } else if (!sample->contains("scan_inputs") || (*sample)["scan_inputs"].empty()) {
        scan.not_applicable = "the session's mesh sample has no scan_inputs";
      } else {
        scan.args = {"scan"};
        std::ostringstream conf;
        bool any_transform = false;
        for (const nlohmann::json& entry : (*sample)["scan_inputs"]) {
          const std::string file = entry.is_string() ? entry.get<std::string>() : entry.value("file", "");
          const std::string path = Absolute(ResolvePath(session_dir, file));
          scan.args.push_back(path);
          scan.inputs.push_back(path);
          Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
          Eigen::Vector3d t = Eigen::Vector3d::Zero();
          if (entry.is_object() && entry.contains("world_from_scan")) {
            any_transform = true;
            const std::vector<double> r = entry["world_from_scan"].at("rotation").get<std::vector<double>>();
            const std::vector<double> p = entry["world_from_scan"].at("translation").get<std::vector<double>>();
            q = Eigen::Quaterniond(r.at(0), r.at(1), r.at(2), r.at(3)).normalized();
            t = Eigen::Vector3d(p.at(0), p.at(1), p.at(2));
          }
          // The Stanford .conf quaternion rotates the common frame into the scan's (scan/scan_io.cc).
          const Eigen::Quaterniond c = q.conjugate();
          conf << "bmesh " << fs::path(path).filename().string() << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' '
               << c.x() << ' ' << c.y() << ' ' << c.z() << ' ' << c.w() << '\n';
        }
        if (any_transform) {
          fs::create_directories(dir / "scan");
          const std::string conf_path = at("scan/inputs.conf");
          std::ofstream(conf_path) << std::setprecision(17) << conf.str();
          scan.args.push_back("--conf");
          scan.args.push_back(conf_path);
        }
        fs::create_directories(dir / "scan");
        for (const char* tail : {"--out", "", "--overwrite"}) scan.args.push_back(tail);
        scan.args[scan.args.size() - 2] = at("scan/mesh.ply");
      }
      execute(scan, [&] {
        nlohmann::json relocated = original;
        AbsolutizePaths(&relocated, session_dir, "");
        relocated["sample"]["file"] = at("scan/mesh.ply");
        relocated["sample"].erase("scan_inputs");
        WriteJsonFile(at("scan/session.json"), relocated);
      });
      if (scan.not_applicable.empty()) current = at("scan/session.json");
    }

    // align: sessions with coded targets; otherwise every photo needs its pose.
    {
      const nlohmann::json manifest = manifest_of(current);
      Stage align{"align",
                  {"align", current, "--out", at("align"), "--overwrite"},
                  {current},
                  {at("align/session.json"), at("align/alignment.json")},
                  ""};
      for (const std::string& photo : PhotoFiles(manifest, current)) align.inputs.push_back(photo);
      if (!manifest.contains("targets")) {
        align.not_applicable = "the session has no targets; its photos' poses are used as given";
        for (size_t i = 0; i < manifest.value("photos", nlohmann::json::array()).size(); ++i) {
          if (!manifest["photos"][i].contains("camera_from_world")) {
            ThrowError(current + ": /photos/" + std::to_string(i) + "/camera_from_world",
                       "missing, and the session has no targets block from which `ibrdf align` could find it");
          }
        }
      }
      execute(align);
      if (align.not_applicable.empty()) current = at("align/session.json");
    }

    // derender.
    {
      const nlohmann::json manifest = manifest_of(current);
      Stage derender{"derender",
                     {"derender", current, "--out", at("samples.npy"), "--overwrite"},
                     {current},
                     {at("samples.npy"), at("samples.npy.json")},
                     ""};
      if (options.pixel_stride != 1) {
        derender.args.push_back("--stride");
        derender.args.push_back(std::to_string(options.pixel_stride));
      }
      for (const std::string& photo : PhotoFiles(manifest, current)) derender.inputs.push_back(photo);
      if (manifest.contains("sample") && manifest["sample"].contains("file") &&
          manifest["sample"]["file"].is_string()) {
        derender.inputs.push_back(ResolvePath(fs::path(current).parent_path().string(), manifest["sample"]["file"]));
      }
      execute(derender);
    }
    const std::vector<std::string> samples_in = {at("samples.npy"), at("samples.npy.json")};

    Stage check{"check",
                {"check", at("samples.npy"), "--out", at("consistency.json"), "--overwrite"},
                samples_in,
                {at("consistency.json")},
                ""};
    if (options.check_regression) check.args.push_back("--regression");
    execute(check);

    Stage compare{"compare", {}, samples_in, {at("truth-comparison.json")}, ""};
    if (truth_path.empty()) {
      compare.not_applicable = "no truth.json beside the session (not synthetic)";
    } else {
      compare.args = {"compare", at("samples.npy"),           "--truth",    truth_path,
                      "--out",   at("truth-comparison.json"), "--overwrite"};
      compare.inputs.push_back(truth_path);
    }
    execute(compare);

    Stage reconstruct{"reconstruct",
                      {"reconstruct", at("samples.npy"), "--out", at("reconstruction"), "--overwrite"},
                      samples_in,
                      {at("reconstruction/summary.json"), at("reconstruction/brdf.binary")},
                      ""};
    if (!truth_path.empty()) {
      reconstruct.args.push_back("--truth");
      reconstruct.args.push_back(truth_path);
      reconstruct.inputs.push_back(truth_path);
    }
    auto pass = [&](const char* flag, double value, double unset) {
      if (value == unset) return;
      std::ostringstream text;
      text << value;
      reconstruct.args.push_back(flag);
      reconstruct.args.push_back(text.str());
    };
    pass("--degree", options.degree, -1);
    pass("--radius-h-deg", options.radius_h_deg, -1.0);
    pass("--radius-d-deg", options.radius_d_deg, -1.0);
    if (!options.fits) reconstruct.args.push_back("--no-fits");
    execute(reconstruct);

    Stage report{
        "report", {"report", run_dir, "--out", at("report"), "--overwrite"}, {}, {at("report/index.html")}, ""};
    if (!options.report) {
      report.not_applicable = "--no-report";
    } else {
      report.inputs = {at("samples.npy"), at("samples.npy.json"), at("consistency.json"),
                       at("reconstruction/summary.json"), at("reconstruction/brdf.binary")};
      if (!truth_path.empty()) report.inputs.push_back(at("truth-comparison.json"));
      for (const Stage& stage : stages) {
        if (outcomes[stage.name].status != "not_applicable") report.inputs.push_back(StampPath(run_dir, stage.name));
      }
    }
    execute(report);

    const nlohmann::json summary =
        BuildSummary(run_dir, Absolute(args->input), stages, outcomes, truth_path, wall.ElapsedSeconds());
    WriteJsonFile(at("summary.json"), summary);
    PrintHeadline(summary);
    Log(1, "-- run: " + FormatSeconds(wall.ElapsedSeconds()) +
               " (stages as recorded: " + FormatSeconds(summary["timings_s"]["stages_total"].get<double>()) + ")");
    Log(1, "summary: " + at("summary.json"));
    if (summary.contains("report")) Log(1, "report: " + summary["report"].get<std::string>());
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(80, AddRunCommand);

}  // namespace ibrdf
