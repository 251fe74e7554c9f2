#include "workflow/stamp.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "workflow/stage_json.h"

namespace fs = std::filesystem;

namespace ibrdf {

FileFingerprint Fingerprint(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return {path, -1, -1};
  return {path, int64_t(st.st_size), int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

nlohmann::json Stamp::ToJson() const {
  nlohmann::json files = nlohmann::json::array();
  for (const FileFingerprint& input : inputs) {
    files.push_back({{"path", input.path}, {"size", input.size}, {"mtime_ns", input.mtime_ns}});
  }
  return {{"stage", stage},  {"build_id", build_id}, {"version", version}, {"args", arguments},
          {"inputs", files}, {"outputs", outputs},   {"seconds", seconds}};
}

Stamp Stamp::Read(const std::string& path) {
  const std::optional<StageJson> json = StageJson::ReadIfExists(path);
  if (!json) ThrowError(path, "no such stamp");
  Stamp stamp;
  stamp.stage = json->String("/stage");
  stamp.build_id = json->String("/build_id", "");  // absent in stamps written before build ids
  stamp.version = json->String("/version", "");
  stamp.arguments = json->Strings("/args");
  const nlohmann::json& inputs = json->Value("/inputs");
  if (!inputs.is_array()) ThrowError(json->Where("/inputs"), "expected an array");
  for (size_t i = 0; i < inputs.size(); ++i) {
    const std::string at = "/inputs/" + std::to_string(i);
    stamp.inputs.push_back({json->String(at + "/path"), json->Integer(at + "/size"), json->Integer(at + "/mtime_ns")});
  }
  stamp.outputs = json->Strings("/outputs");
  stamp.seconds = json->Number("/seconds");
  return stamp;
}

Stamp StampOf(const Stage& stage, const std::string& build_id, const std::string& version, double seconds) {
  Stamp stamp;
  stamp.stage = stage.name;
  stamp.build_id = build_id;
  stamp.version = version;
  stamp.arguments = stage.arguments;
  for (const std::string& input : stage.inputs) stamp.inputs.push_back(Fingerprint(input));
  stamp.outputs = stage.outputs;
  stamp.seconds = seconds;
  return stamp;
}

std::string StampPath(const std::string& run_dir, const std::string& stage) {
  return (fs::path(run_dir) / "stamps" / (stage + ".json")).string();
}

std::string WhyStale(const std::string& run_dir, const Stage& stage, const std::string& build_id) {
  const std::string stamp_path = StampPath(run_dir, stage.name);
  if (!fs::exists(stamp_path)) return "no record of a completed run";
  Stamp stamp;
  try {
    stamp = Stamp::Read(stamp_path);
  } catch (const Error&) {
    return "its record is unreadable";
  }
  if (stamp.build_id != build_id) return "the ibrdf binary changed";
  if (stamp.arguments != stage.arguments) return "options changed";
  std::vector<FileFingerprint> now;
  int64_t newest_input = 0;
  for (const std::string& input : stage.inputs) {
    now.push_back(Fingerprint(input));
    newest_input = std::max(newest_input, now.back().mtime_ns);
  }
  if (stamp.inputs != now) return "an input changed";
  for (const std::string& output : stage.outputs) {
    const int64_t mtime = Fingerprint(output).mtime_ns;
    if (mtime < 0) return output + " is missing";
    if (mtime < newest_input) return output + " is older than an input";
  }
  return "";
}

}  // namespace ibrdf
