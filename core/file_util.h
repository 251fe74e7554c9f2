// Files that appear only when complete: outputs are written under a temporary name beside their final
// path and renamed into place (an atomic rename on one file system).
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

// A file being written. Write to temporary_path(); Commit() renames it to the final path. If Commit()
// is never called (an exception), the destructor removes the temporary file and the final path is
// untouched. The temporary name keeps the extension, so extension-driven writers (OpenImageIO) work.
class AtomicFile {
 public:
  explicit AtomicFile(std::string final_path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& temporary_path() const { return temporary_path_; }
  const std::string& final_path() const { return final_path_; }
  void Commit();

 private:
  std::string final_path_;
  std::string temporary_path_;
  bool committed_ = false;
};

// A directory being written, committed by rename like AtomicFile. If the final directory exists it is
// replaced only on Commit() and only when `replace_existing` is set; otherwise the constructor throws.
class AtomicDirectory {
 public:
  AtomicDirectory(std::string final_path, bool replace_existing);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  const std::string& temporary_path() const { return temporary_path_; }
  void Commit();

 private:
  std::string final_path_;
  std::string temporary_path_;
  bool replace_existing_;
  bool committed_ = false;
};

// Moves two finished files into place as one unit: `manifest` (the sidecar that describes `data`) is
// removed first and moved into place last, so a process stopped in between leaves `data` without a
// manifest (visibly incomplete), never a new `data` beside the previous run's manifest.
void CommitWithManifest(AtomicFile* data, AtomicFile* manifest);

// Removes the temporaries a killed writer of `final_path` left beside it (".NAME.tmp-PID-N..." whose
// process no longer exists); those of live processes are kept. Called by AtomicFile and
// AtomicDirectory, so each stage cleans up after its own interrupted runs. Returns the paths removed.
std::vector<std::string> RemoveStaleTemporariesOf(const std::string& final_path, bool is_directory);

// Throws Error unless `path` is an existing regular file.
void RequireFile(const std::string& path, const std::string& what);

// Resolves `path` against `base_dir` unless it is absolute.
std::string ResolvePath(const std::string& base_dir, const std::string& path);

// True if two paths name the same existing file (or the same path when either does not exist).
bool SameFile(const std::string& a, const std::string& b);

// The extension of `path` in lower case, with its dot (".png", ".cr2"; "" when it has none).
std::string LowerExtension(const std::string& path);

}  // namespace ibrdf
