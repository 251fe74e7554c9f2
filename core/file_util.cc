#include "core/file_util.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <filesystem>

#include "core/error.h"
#include "core/interruption.h"
#include "core/logging.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {
std::string UniqueSuffix() {
  static std::atomic<int> counter{0};
  return ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}
}  // namespace

AtomicFile::AtomicFile(std::string final_path) : final_path_(std::move(final_path)) {
  const fs::path final(final_path_);
  if (final.has_parent_path() && !fs::is_directory(final.parent_path())) {
    ThrowError(final_path_, "output folder " + final.parent_path().string() + " does not exist");
  }
  const fs::path temporary =
      final.parent_path() / ("." + final.stem().string() + UniqueSuffix() + final.extension().string());
  temporary_path_ = temporary.string();
  RemoveStaleTemporariesOf(final_path_, false);
  RegisterTemporary(temporary_path_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temporary_path_, ignored);
    UnregisterTemporary(temporary_path_);
  }
}

void AtomicFile::Commit() {
  std::error_code error;
  fs::rename(temporary_path_, final_path_, error);
  if (error) ThrowError(final_path_, "cannot move the finished file into place: " + error.message());
  committed_ = true;
  UnregisterTemporary(temporary_path_);
}

AtomicDirectory::AtomicDirectory(std::string final_path, bool replace_existing)
    : final_path_(std::move(final_path)), replace_existing_(replace_existing) {
  while (!final_path_.empty() && final_path_.back() == '/') final_path_.pop_back();
  if (fs::exists(final_path_) && !replace_existing_) {
    ThrowError(final_path_, "already exists (pass --overwrite to replace it)");
  }
  const fs::path final(final_path_);
  const fs::path parent = final.has_parent_path() ? final.parent_path() : fs::path(".");
  if (!fs::is_directory(parent)) ThrowError(final_path_, "parent folder does not exist");
  temporary_path_ = (parent / ("." + final.filename().string() + UniqueSuffix())).string();
  RemoveStaleTemporariesOf(final_path_, true);
  RegisterTemporary(temporary_path_);
  fs::create_directories(temporary_path_);
}

AtomicDirectory::~AtomicDirectory() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove_all(temporary_path_, ignored);
    UnregisterTemporary(temporary_path_);
  }
}

void AtomicDirectory::Commit() {
  std::error_code error;
  std::string old_path;
  if (fs::exists(final_path_)) {
    if (!replace_existing_) ThrowError(final_path_, "appeared while writing; not replaced");
    old_path = temporary_path_ + ".old";
    fs::rename(final_path_, old_path, error);
    if (error) ThrowError(final_path_, "cannot move the old folder aside: " + error.message());
  }
  fs::rename(temporary_path_, final_path_, error);
  if (error) {
    std::error_code ignored;
    if (!old_path.empty()) fs::rename(old_path, final_path_, ignored);  // put the old folder back
    ThrowError(final_path_, "cannot move the finished folder into place: " + error.message());
  }
  committed_ = true;
  UnregisterTemporary(temporary_path_);
  if (!old_path.empty()) fs::remove_all(old_path, error);
}

void CommitWithManifest(AtomicFile* data, AtomicFile* manifest) {
  std::error_code error;
  fs::remove(manifest->final_path(), error);
  if (error) ThrowError(manifest->final_path(), "cannot remove the previous file: " + error.message());
  data->Commit();
  manifest->Commit();
}

std::vector<std::string> RemoveStaleTemporariesOf(const std::string& final_path, bool is_directory) {
  std::vector<std::string> removed;
  const fs::path final(final_path);
  const fs::path parent = final.has_parent_path() ? final.parent_path() : fs::path(".");
  const std::string prefix = "." + (is_directory ? final.filename().string() : final.stem().string()) + ".tmp-";
  std::error_code error;
  fs::directory_iterator it(parent, error);
  if (error) return removed;
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    if (!is_directory && !final.extension().empty() &&
        name.find(final.extension().string(), prefix.size()) == std::string::npos) {
      continue;  // another file of the same stem
    }
    const int pid = std::atoi(name.c_str() + prefix.size());
    if (pid <= 0 || ::kill(pid, 0) == 0 || errno != ESRCH) continue;  // its writer may still run
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
    removed.push_back(entry.path().string());
    Log(1, "removed the leftover of an interrupted write: " + entry.path().string());
  }
  return removed;
}

void RequireFile(const std::string& path, const std::string& what) {
  if (!fs::exists(path)) ThrowError(path, what + " does not exist");
  if (!fs::is_regular_file(path)) ThrowError(path, what + " is not a regular file");
}

std::string ResolvePath(const std::string& base_dir, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(base_dir) / path).lexically_normal().string();
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  if (fs::exists(a) && fs::exists(b)) return fs::equivalent(a, b, error);
  return fs::weakly_canonical(a, error) == fs::weakly_canonical(b, error);
}

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace ibrdf
