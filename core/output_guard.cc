#include "core/output_guard.h"

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

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
    const std::filesystem::path in = Resolved(input);
    if (IsWithin(in, out)) {
      ThrowError(output, "holds " + input +
                             ", an input of this stage; writing there would replace it (--overwrite "
                             "does not change this)");
    }
    // The writer of `output` removes leftovers named ".STEM.tmp-PID..." beside it (core/file_util.h).
    const std::string temporary_prefix = "." + out.stem().string() + ".tmp-";
    if (in.parent_path() == out.parent_path() && in.filename().string().rfind(temporary_prefix, 0) == 0) {
      ThrowError(output, "would remove " + input +
                             ", an input of this stage named like a temporary of this output (--overwrite "
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

namespace {
// The "format" of the JSON file at `path` ("" when it is no JSON object or has none).
std::string JsonFormatOf(const std::string& path) {
  std::ifstream in(path);
  const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
  if (!json.is_object()) return "";
  const auto format = json.find("format");
  return format != json.end() && format->is_string() ? format->get<std::string>() : "";
}
}  // namespace

void RequireWritableOutputs(const std::string& output, const std::vector<CompanionFile>& companions, bool overwrite,
                            const std::vector<std::string>& inputs) {
  RequireWritableOutput(output, overwrite, inputs);
  for (const CompanionFile& companion : companions) {
    RequireWritableOutput(companion.path, overwrite, inputs);
    if (!std::filesystem::exists(companion.path)) continue;
    const std::string format = JsonFormatOf(companion.path);
    if (format != companion.format) {
      ThrowError(companion.path, "exists and is not a file this stage wrote (" +
                                     (format.empty() ? std::string("no \"format\"") : "format \"" + format + "\"") +
                                     ", expected \"" + companion.format + "\"); it is written beside " + output +
                                     " and is not replaced, --overwrite or not: choose another --out");
    }
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
