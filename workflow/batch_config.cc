#include "workflow/batch_config.h"

#include <glob.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string Absolute(const fs::path& path) { return fs::absolute(path).lexically_normal().string(); }

bool IsPattern(const std::string& text) { return text.find_first_of("*?[") != std::string::npos; }

// A folder or file that `ibrdf run` accepts: a folder holding session.json or recipe.json, or one of
// those files.
bool IsMeasurementInput(const fs::path& path) {
  std::error_code ignored;
  if (fs::is_directory(path, ignored)) {
    return fs::exists(path / "session.json", ignored) || fs::exists(path / "recipe.json", ignored);
  }
  return path.filename() == "session.json" || path.filename() == "recipe.json";
}

// The entry's default name: the folder's name (the parent folder's for session.json or recipe.json).
std::string DefaultName(const fs::path& input) {
  fs::path path = fs::path(Absolute(input));
  if (path.filename() == "session.json" || path.filename() == "recipe.json") path = path.parent_path();
  return path.filename().string();
}

bool ValidName(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

// The glob's matches that `ibrdf run` accepts, sorted; an Error naming the field when there is none.
std::vector<std::string> ExpandPattern(const std::string& pattern, const std::string& where) {
  glob_t matches{};
  const int code = glob(pattern.c_str(), GLOB_NOSORT, nullptr, &matches);
  std::vector<std::string> inputs;
  for (size_t i = 0; code == 0 && i < matches.gl_pathc; ++i) {
    if (IsMeasurementInput(matches.gl_pathv[i])) inputs.push_back(Absolute(matches.gl_pathv[i]));
  }
  globfree(&matches);
  if (inputs.empty()) {
    ThrowError(where,
               "the pattern \"" + pattern + "\" matches no session folder, session.json, recipe folder or recipe.json");
  }
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

// The stages' arguments: the batch config's key and `ibrdf run`'s flag for each (one string, split at
// spaces).
struct StageArgsKey {
  const char* key;
  const char* flag;
  std::vector<std::string> MeasurementOptions::*member;
};
const StageArgsKey kStageArgs[] = {{"scan_args", "--scan-args", &MeasurementOptions::scan_args},
                                   {"response_args", "--response-args", &MeasurementOptions::response_args},
                                   {"align_args", "--align-args", &MeasurementOptions::align_args},
                                   {"lights_args", "--lights-args", &MeasurementOptions::lights_args},
                                   {"colour_args", "--colour-args", &MeasurementOptions::colour_args},
                                   {"derender_args", "--derender-args", &MeasurementOptions::derender_args},
                                   {"check_args", "--check-args", &MeasurementOptions::check_args},
                                   {"reconstruct_args", "--reconstruct-args", &MeasurementOptions::reconstruct_args},
                                   {"uniformity_args", "--uniformity-args", &MeasurementOptions::uniformity_args},
                                   {"materials_args", "--materials-args", &MeasurementOptions::materials_args},
                                   {"report_args", "--report-args", &MeasurementOptions::report_args}};

// Reads an "options" block on top of `options`.
void ReadOptions(JsonObject block, MeasurementOptions* options) {
  options->pixel_stride = block.Integer("stride", options->pixel_stride);
  options->degree = block.Integer("degree", options->degree);
  options->radius_h_deg = block.Number("radius_h_deg", options->radius_h_deg);
  options->radius_d_deg = block.Number("radius_d_deg", options->radius_d_deg);
  options->fits = block.Boolean("fits", options->fits);
  options->report = block.Boolean("report", options->report);
  options->check_regression = block.Boolean("check_regression", options->check_regression);
  options->spatial = block.Boolean("spatial", options->spatial);
  for (const StageArgsKey& stage : kStageArgs) {
    if (!block.Has(stage.key)) continue;
    std::vector<std::string>& words = options->*stage.member;
    words.clear();  // an entry's own replaces the batch's
    std::istringstream text(block.String(stage.key));
    for (std::string word; text >> word;) words.push_back(word);
  }
  block.Finish();
  std::string why;
  if (!options->Check(&why)) ThrowError(block.Where(), why);
}

int PositiveInteger(JsonObject* root, const std::string& key, int fallback) {
  const int value = root->Integer(key, fallback);
  if (value < 1) ThrowError(root->Where(key), "must be at least 1, got " + std::to_string(value));
  return value;
}

}  // namespace

std::string BatchConfig::LibraryDir() const { return (fs::path(out_dir) / "library").string(); }

BatchConfig ReadBatchConfig(const std::string& path) {
  const nlohmann::json value = ReadJsonFile(path);
  if (!value.is_object())
    ThrowError(path, "expected a JSON object (an ibrdf-batch config), got " + JsonTypeName(value));
  JsonObject root(value, path);
  if (root.String("format") != "ibrdf-batch") ThrowError(root.Where("format"), "expected \"ibrdf-batch\"");
  if (root.Integer("version") != 1) ThrowError(root.Where("version"), "expected 1");
  const fs::path base = fs::path(Absolute(path)).parent_path();

  BatchConfig config;
  config.path = Absolute(path);
  config.out_dir = Absolute(base / root.String("out"));
  config.threads_per_job = PositiveInteger(&root, "threads_per_job", config.threads_per_job);
  config.mem_mb_per_job = PositiveInteger(&root, "mem_mb_per_job", config.mem_mb_per_job);
  config.runtime_min_per_job = PositiveInteger(&root, "runtime_min_per_job", config.runtime_min_per_job);
  MeasurementOptions options;
  if (root.Has("options")) ReadOptions(root.Object("options"), &options);
  if (root.Has("compare")) {
    const nlohmann::json& compare = root.Raw("compare");
    if (!compare.is_array()) ThrowError(root.Where("compare"), "expected an array of material names");
    for (size_t i = 0; i < compare.size(); ++i) {
      if (!compare[i].is_string()) {
        ThrowError(root.Where("compare") + "/" + std::to_string(i), "expected a name, got " + JsonTypeName(compare[i]));
      }
      config.compare.push_back(compare[i].get<std::string>());
    }
  }

  const nlohmann::json& sessions = root.Raw("sessions");
  if (!sessions.is_array() || sessions.empty()) {
    ThrowError(root.Where("sessions"), "expected a non-empty array of session folders, recipes or patterns");
  }
  root.Finish();  // unknown keys first: a misspelt "options" must not go unnoticed behind a session error
  std::map<std::string, std::string> seen;  // name -> where
  for (size_t i = 0; i < sessions.size(); ++i) {
    const std::string where = root.Where("sessions") + "/" + std::to_string(i);
    std::vector<std::string> inputs;
    std::string name;
    MeasurementOptions entry_options = options;
    std::string text;
    if (sessions[i].is_string()) {
      text = sessions[i].get<std::string>();
    } else if (sessions[i].is_object()) {
      JsonObject entry(sessions[i], path, "/sessions/" + std::to_string(i));
      text = entry.String("path");
      name = entry.String("name", "");
      if (entry.Has("options")) ReadOptions(entry.Object("options"), &entry_options);
      entry.Finish();
      if (IsPattern(text)) ThrowError(where + "/path", "a named entry is one session, not a pattern");
    } else {
      ThrowError(where,
                 "expected a path, a pattern or {\"path\", \"name\", \"options\"}, got " + JsonTypeName(sessions[i]));
    }
    const std::string resolved = (base / text).string();
    if (IsPattern(text)) {
      inputs = ExpandPattern(resolved, where);
    } else {
      if (!fs::exists(resolved)) ThrowError(where, "\"" + text + "\": " + Absolute(resolved) + " does not exist");
      if (!IsMeasurementInput(resolved)) {
        ThrowError(where, Absolute(resolved) + " is neither a session (folder or session.json) nor a recipe");
      }
      inputs = {Absolute(resolved)};
    }
    for (const std::string& input : inputs) {
      BatchEntry entry;
      entry.name = name.empty() ? DefaultName(input) : name;
      if (!ValidName(entry.name)) {
        ThrowError(where, "the name \"" + entry.name +
                              "\" may hold only letters, digits, '.', '_' and '-' (give the entry a \"name\")");
      }
      const auto [it, inserted] = seen.emplace(entry.name, where);
      if (!inserted) {
        ThrowError(where, "a second session named \"" + entry.name + "\" (the first: " + it->second +
                              "); give one of them {\"path\": ..., \"name\": ...}");
      }
      entry.input = input;
      entry.run_dir = (fs::path(config.out_dir) / "runs" / entry.name).string();
      entry.log_path = (fs::path(config.out_dir) / "logs" / (entry.name + ".log")).string();
      entry.options = entry_options;
      config.entries.push_back(entry);
    }
  }
  return config;
}

std::vector<std::string> RunArguments(const BatchEntry& entry) {
  std::vector<std::string> arguments = {"run", entry.input, "--out", entry.run_dir};
  const MeasurementOptions& o = entry.options;
  auto number = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  if (o.pixel_stride != 1) arguments.insert(arguments.end(), {"--stride", std::to_string(o.pixel_stride)});
  if (o.degree != -1) arguments.insert(arguments.end(), {"--degree", std::to_string(o.degree)});
  if (o.radius_h_deg != -1.0) arguments.insert(arguments.end(), {"--radius-h-deg", number(o.radius_h_deg)});
  if (o.radius_d_deg != -1.0) arguments.insert(arguments.end(), {"--radius-d-deg", number(o.radius_d_deg)});
  if (!o.fits) arguments.push_back("--no-fits");
  if (!o.report) arguments.push_back("--no-report");
  if (o.check_regression) arguments.push_back("--check-regression");
  if (o.spatial) arguments.push_back("--spatial");
  for (const StageArgsKey& stage : kStageArgs) {
    const std::vector<std::string>& words = o.*stage.member;
    if (words.empty()) continue;
    std::string joined;
    for (const std::string& word : words) joined += (joined.empty() ? "" : " ") + word;
    arguments.insert(arguments.end(), {stage.flag, joined});
  }
  return arguments;
}

}  // namespace ibrdf
