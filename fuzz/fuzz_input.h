// Helpers of the fuzz targets. The readers take paths, so each input is handed to them as files of a
// scratch folder of this process, made once: each entry is a link to a memory file (memfd_create,
// /proc/self/fd/N) that every execution rewrites in place, so a reader opens the path it would open
// for the CLI while nothing is written to disk per execution (one file written per execution held
// the runs to a few hundred executions per second). A reader may throw only ibrdf::Error, and its
// message must name a file of the scratch folder (the rule of the readers: one line naming the file
// and what is wrong); any other exception, or a message naming no file, aborts, which libFuzzer and
// the replay report.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"

namespace ibrdf::fuzz {

// The scratch folder and its memory files; removed when the process exits.
class MemoryFiles {
 public:
  static MemoryFiles& Get() {
    static MemoryFiles* files = new MemoryFiles();
    return *files;
  }

  const std::string& dir() const { return dir_; }

  // Sets the content of dir()/NAME (a plain name) to the bytes; returns its path.
  std::string Put(const std::string& name, const void* data, size_t size) {
    auto it = fds_.find(name);
    if (it == fds_.end()) {
      const int fd = memfd_create(name.c_str(), MFD_CLOEXEC);
      if (fd < 0) Die("memfd_create");
      const std::string link = "/proc/self/fd/" + std::to_string(fd);
      std::error_code error;
      std::filesystem::create_symlink(link, dir_ + "/" + name, error);
      if (error) Die("symlink " + dir_ + "/" + name);
      it = fds_.emplace(name, fd).first;
    }
    const int fd = it->second;
    if (ftruncate(fd, 0) != 0) Die("ftruncate");
    const char* bytes = static_cast<const char*>(data);
    size_t written = 0;
    while (written < size) {
      const ssize_t n = pwrite(fd, bytes + written, size - written, static_cast<off_t>(written));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) Die("pwrite");
      written += static_cast<size_t>(n);
    }
    return dir_ + "/" + name;
  }
  std::string Put(const std::string& name, const std::string& bytes) { return Put(name, bytes.data(), bytes.size()); }

  // A plain file dir()/RELATIVE written once (a fixture the input refers to: a material, a session
  // folder); returns its path.
  std::string Fixture(const std::string& relative, const std::string& bytes) {
    const std::string path = dir_ + "/" + relative;
    if (!std::filesystem::exists(path)) {
      std::filesystem::create_directories(std::filesystem::path(path).parent_path());
      std::ofstream out(path, std::ios::binary);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    return path;
  }

 private:
  MemoryFiles() {
    const char* base = std::getenv("TMPDIR");
    dir_ = std::string(base && *base ? base : "/tmp") + "/ibrdf-fuzz-" + std::to_string(getpid());
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
    std::filesystem::create_directories(dir_);
    std::atexit([] {
      std::error_code error;
      std::filesystem::remove_all(Get().dir_, error);
    });
  }

  [[noreturn]] static void Die(const std::string& what) {
    std::perror(what.c_str());
    std::abort();
  }

  std::string dir_;
  std::map<std::string, int> fds_;
};

inline std::string ScratchDir() { return MemoryFiles::Get().dir(); }

// dir()/NAME holding the bytes.
inline std::string PutFile(const std::string& name, const uint8_t* data, size_t size) {
  return MemoryFiles::Get().Put(name, data, size);
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
// for anything else (and for no exception when MustFail()). With IBRDF_FUZZ_VERBOSE set, prints each
// refusal (to see how deep a corpus reaches).
inline void ExpectCleanFailure(const std::string& dir, const std::function<void()>& read) {
  try {
    read();
    if (MustFail()) {
      std::fprintf(stderr, "a regression input was accepted: the reader must refuse it\n");
      std::abort();
    }
  } catch (const Error& error) {
    const std::string message = error.what();
    static const bool verbose = std::getenv("IBRDF_FUZZ_VERBOSE") != nullptr;
    if (verbose) std::fprintf(stderr, "  refused: %s\n", message.c_str());
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
