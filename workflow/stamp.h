// The record of a completed stage, DIR/stamps/<stage>.json, and the staleness rule built on it: a stage
// is up to date only when the same binary (its build id, build_id.h) ran it with the same options, its
// inputs still have the recorded size and modification time, and its outputs exist and are not older
// than any input (docs/workflow.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "workflow/stage.h"

namespace ibrdf {

// A file's size and modification time, as recorded for a stage's input.
struct FileFingerprint {
  std::string path;
  int64_t size = -1;      // bytes; -1 when the file is absent
  int64_t mtime_ns = -1;  // modification time, nanoseconds since the epoch; -1 when absent

  bool operator==(const FileFingerprint& other) const {
    return path == other.path && size == other.size && mtime_ns == other.mtime_ns;
  }
  bool operator!=(const FileFingerprint& other) const { return !(*this == other); }
};

// The fingerprint of `path` now.
FileFingerprint Fingerprint(const std::string& path);

struct Stamp {
  std::string stage;                    // the stage's name
  std::string build_id;                 // the binary that ran it (ExecutableBuildId()); "" in older stamps
  std::string version;                  // its version string, for the reader (kIbrdfVersionLine, core/version.h)
  std::vector<std::string> arguments;   // the stage's options (its command line)
  std::vector<FileFingerprint> inputs;  // its inputs when it ran
  std::vector<std::string> outputs;     // what it left behind
  double seconds = 0.0;                 // its wall-clock time

  // The stamp file's JSON: {"stage", "build_id", "version", "args", "inputs": [{"path", "size",
  // "mtime_ns"}], "outputs", "seconds"}.
  nlohmann::json ToJson() const;
  // Reads a stamp file; a missing or wrongly typed field is an Error naming the file and the field.
  static Stamp Read(const std::string& path);
};

// The stamp `stage` gets when it completes now.
Stamp StampOf(const Stage& stage, const std::string& build_id, const std::string& version, double seconds);

// DIR/stamps/<stage>.json.
std::string StampPath(const std::string& run_dir, const std::string& stage);

// Empty when `stage` is up to date in `run_dir` for the binary `build_id`; otherwise why it must run:
// "no record of a completed run", "its record is unreadable", "the ibrdf binary changed", "options
// changed", "an input changed", "<output> is missing", "<output> is older than an input".
std::string WhyStale(const std::string& run_dir, const Stage& stage, const std::string& build_id);

}  // namespace ibrdf
