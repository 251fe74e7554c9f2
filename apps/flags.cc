// The subcommand registry and the flag helpers of apps/commands.h.
#include <algorithm>
#include <set>
#include <utility>

#include "apps/commands.h"
#include "core/logging.h"
#include "core/session.h"

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

void AddOutputFlags(CLI::App& app, std::string& out, bool& overwrite, const std::string& out_help,
                    const std::string& overwrite_help) {
  app.add_option("--out", out, out_help)->required();
  app.add_flag("--overwrite", overwrite, overwrite_help);
}

CLI::Option* AddClearingFlag(CLI::App& app, const std::string& name, bool& value, const std::string& help) {
  return app.add_flag_callback(name, [&value] { value = false; }, help);
}

CLI::Option* AddMillimetres(CLI::App& app, const std::string& name, double& metres, const std::string& help) {
  return app.add_option_function<double>(name, [&metres](double mm) { metres = 1e-3 * mm; }, help)
      ->default_str(CLI::detail::to_string(1e3 * metres));
}

std::vector<std::string> SessionInputs(const Session& session) {
  std::vector<std::string> inputs = session.InputFiles();
  inputs.push_back(session.manifest_path);
  inputs.push_back(session.directory);
  return inputs;
}

void WarnDeprecatedOption(const std::string& old_name, const std::string& new_name) {
  static std::set<std::string> warned;
  if (!warned.insert(old_name).second) return;
  Log(1, "warning: " + old_name + " is deprecated; use " + new_name + " (the old name goes in the next release)");
}

}  // namespace ibrdf
