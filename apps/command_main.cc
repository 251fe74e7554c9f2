// The main() of each subcommand's binary `ibrdf-<name>` (apps/CMakeLists.txt, ibrdf_add_command): the
// front end (apps/main.cc) execs it with the whole command line. It parses the global flags wherever
// they are (the subcommand falls through to them), runs the one subcommand linked in, and maps
// failures to exit codes: 2 for a usage error, 1 for an error in the input, 70 for a bug.
#include <iostream>
#include <memory>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/global_flags.h"
#include "core/error.h"
#include "core/logging.h"

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
