#include <filesystem>

#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {

void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs) {
  for (const std::string& input : inputs) {
    if (SameFile(output, input)) ThrowError(output, "is an input of this stage; no stage overwrites its inputs");
  }
  if (std::filesystem::exists(output) && !overwrite) {
    ThrowError(output, "already exists (pass --overwrite to replace it)");
  }
  const std::filesystem::path parent = std::filesystem::path(output).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    ThrowError(output, "output folder " + parent.string() + " does not exist");
  }
}

}  // namespace ibrdf
