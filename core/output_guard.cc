#include "core/output_guard.h"

#include <filesystem>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

// The absolute, symlink-resolved form of `path` (its existing part resolved, the rest appended).
std::filesystem::path Resolved(const std::string& path) {
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(path, error);
  std::filesystem::path resolved = std::filesystem::weakly_canonical(absolute, error);
  if (error) resolved = absolute.lexically_normal();
  // "dir/" and "dir" are the same folder.
  if (!resolved.empty() && resolved.filename().empty()) resolved = resolved.parent_path();
  return resolved;
}

// True if `inner` is `outer` or lies inside it, compared path component by component.
bool IsWithin(const std::filesystem::path& inner, const std::filesystem::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

void RequireOutputOutsideInputs(const std::string& output, const std::vector<std::string>& inputs) {
  if (output.empty()) ThrowError("--out", "is empty");
  const std::filesystem::path out = Resolved(output);
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    if (SameFile(output, input))
      ThrowError(output, "is an input of this stage (" + input + "); no stage overwrites its inputs");
    if (IsWithin(Resolved(input), out)) {
      ThrowError(output, "holds " + input +
                             ", an input of this stage; writing there would replace it (--overwrite "
                             "does not change this)");
    }
  }
}

void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs) {
  RequireOutputOutsideInputs(output, inputs);
  if (std::filesystem::exists(output) && !overwrite) {
    ThrowError(output, "already exists (pass --overwrite to replace it)");
  }
  const std::filesystem::path parent = std::filesystem::path(output).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    ThrowError(output, "output folder " + parent.string() + " does not exist");
  }
}

std::vector<std::string> FilesUnder(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) return files;
  for (std::filesystem::recursive_directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    if (it->is_regular_file(error)) files.push_back(it->path().string());
  }
  return files;
}

}  // namespace ibrdf
