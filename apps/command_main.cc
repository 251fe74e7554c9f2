// The main() of each subcommand's binary `ibrdf-<name>` (apps/CMakeLists.txt, ibrdf_add_command): the
// front end (apps/main.cc) execs it with the whole command line. It parses the global flags wherever
// they are (the subcommand falls through to them), runs the one subcommand linked in, and maps
// failures to exit codes: 2 for a usage error, 1 for an error in the input, 70 for a bug.
// Also the subcommand registry and the flag helpers of apps/commands.h.
#include <iostream>
#include <map>
#include <memory>
#include <set>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/global_flags.h"
#include "core/error.h"

namespace ibrdf {
namespace {
// By order; a multimap keeps the registration order of equal orders.
std::multimap<int, AddCommandFunction>& Registry() {
  static std::multimap<int, AddCommandFunction> registry;
  return registry;
}
}  // namespace

CommandRegistrar::CommandRegistrar(int order, AddCommandFunction add) { Registry().emplace(order, add); }

std::vector<AddCommandFunction> RegisteredCommands() {
  std::vector<AddCommandFunction> out;
  for (const auto& [order, add] : Registry()) out.push_back(add);
  return out;
}

void AddOutputFlags(CLI::App& app, std::string& out, bool& overwrite, const std::string& out_help,
                    const std::string& overwrite_help) {
  app.add_option("--out", out, out_help)->required();
  app.add_flag("--overwrite", overwrite, overwrite_help);
}

CLI::Option* AddClearingFlag(CLI::App& app, const std::string& name, bool& value, const std::string& help) {
  return app.add_flag_callback(
      name, [&value] { value = false; }, help);
}

CLI::Option* AddMillimetres(CLI::App& app, const std::string& name, double& metres, const std::string& help) {
  return app
      .add_option_function<double>(
          name, [&metres](double mm) { metres = 1e-3 * mm; }, help)
      ->default_str(CLI::detail::to_string(1e3 * metres));
}

void WarnDeprecatedOption(const std::string& old_name, const std::string& new_name) {
  static std::set<std::string> warned;
  if (!warned.insert(old_name).second) return;
  Log(1, "warning: " + old_name + " is deprecated; use " + new_name + " (the old name goes in the next release)");
}

}  // namespace ibrdf

int main(int argc, char** argv) {
  CLI::App app{"", "ibrdf"};
  int verbosity = 2, threads = 0;
  ibrdf::AddGlobalFlags(app, verbosity, threads);
  for (ibrdf::AddCommandFunction add : ibrdf::RegisteredCommands()) add(app);
  // Global flags after the subcommand's own arguments (`ibrdf derender S --out x.npy -q`).
  for (CLI::App* command : app.get_subcommands({})) command->fallthrough();

  std::unique_ptr<tbb::global_control> thread_limit;
  app.parse_complete_callback([&] {
    ibrdf::SetVerbosity(verbosity);
    if (threads > 0) {
      thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
    }
  });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Prints the help, the version, or the message and a pointer to --help; only the first two succeed.
    return app.exit(e) == 0 ? 0 : ibrdf::kUsageErrorExitCode;
  } catch (const ibrdf::InternalError& e) {
    std::cerr << "ibrdf: bug: " << e.what() << " (please report it)" << std::endl;
    return 70;
  } catch (const std::exception& e) {  // ibrdf::Error (bad input) and every other failure
    std::cerr << "ibrdf: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
