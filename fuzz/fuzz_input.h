// Helpers of the fuzz targets: the readers take paths, so each input is written to files in a scratch
// folder of this process first. A reader may throw only ibrdf::Error, and its message must name a file
// of the scratch folder (the rule of the readers: one line naming the file and what is wrong); any
// other exception, or a message naming no file, aborts, which libFuzzer and the replay report.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "core/error.h"

namespace ibrdf::fuzz {

// The scratch folder of this process, created once, emptied on every call.
inline std::string ScratchDir() {
  static const std::string dir = [] {
    const char* base = std::getenv("TMPDIR");
    const std::string path = std::string(base && *base ? base : "/tmp") + "/ibrdf-fuzz-" + std::to_string(getpid());
    std::filesystem::create_directories(path);
    return path;
  }();
  std::error_code ignored;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) std::filesystem::remove_all(entry.path(), ignored);
  return dir;
}

inline void WriteBytes(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// Splits an input into `count` files at the marker (the corpus files hold it between the parts);
// missing parts are empty.
inline std::vector<std::string> SplitParts(const uint8_t* data, size_t size, size_t count) {
  static const std::string kMarker = "\n#IBRDF-NEXT-FILE#\n";
  const std::string all(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t start = 0;
  while (parts.size() + 1 < count) {
    const size_t at = all.find(kMarker, start);
    if (at == std::string::npos) break;
    parts.push_back(all.substr(start, at - start));
    start = at + kMarker.size();
  }
  parts.push_back(all.substr(start));
  parts.resize(count);
  return parts;
}

// Set by the replay for the inputs of regressions/: each was accepted silently once and must now be
// refused by every read of the target.
inline bool& MustFail() {
  static bool must_fail = false;
  return must_fail;
}

// Runs `read`; returns normally for no exception or an ibrdf::Error naming a file under `dir`, aborts
// for anything else (and for no exception when MustFail()).
inline void ExpectCleanFailure(const std::string& dir, const std::function<void()>& read) {
  try {
    read();
    if (MustFail()) {
      std::fprintf(stderr, "a regression input was accepted: the reader must refuse it\n");
      std::abort();
    }
  } catch (const Error& error) {
    const std::string message = error.what();
    if (message.find(dir) == std::string::npos) {
      std::fprintf(stderr, "reader error names no input file: %s\n", message.c_str());
      std::abort();
    }
  } catch (const std::exception& other) {
    std::fprintf(stderr, "reader let a non-ibrdf exception escape: %s\n", other.what());
    std::abort();
  }
}

}  // namespace ibrdf::fuzz
