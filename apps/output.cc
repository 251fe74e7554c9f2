#include <algorithm>
#include <filesystem>
#include <utility>

#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {
std::vector<std::pair<int, AddCommandFunction>>& Registry() {
  static std::vector<std::pair<int, AddCommandFunction>> registry;
  return registry;
}
}  // namespace

CommandRegistrar::CommandRegistrar(int order, AddCommandFunction add) { Registry().emplace_back(order, add); }

std::vector<AddCommandFunction> RegisteredCommands() {
  std::vector<std::pair<int, AddCommandFunction>> sorted = Registry();
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<AddCommandFunction> out;
  for (const auto& entry : sorted) out.push_back(entry.second);
  return out;
}

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
