// The main() of each subcommand's binary `ibrdf-<name>` (apps/CMakeLists.txt, ibrdf_add_command): the
// front end (apps/main.cc) execs it with the whole command line. It parses the global flags wherever
// they are (the subcommand falls through to them), runs the one subcommand linked in, and maps
// failures to exit codes: 2 for a usage error, 1 for an error in the input, 70 for a bug.
#include <cstdlib>
#include <iostream>
#include <memory>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/version.h"

int main(int argc, char** argv) {
  CLI::App app{
      "ibrdf: image-based BRDF measurement (after Marschner et al. 1999).\n"
      "Photograph a curved sample under one small light from many positions; every pixel is a BRDF sample.",
      "ibrdf"};
  app.require_subcommand(1);
  app.set_version_flag("--version", ibrdf::kIbrdfVersionLine);
  int verbosity = 2;
  int threads = 0;
  app.add_flag_callback(
      "-q,--quiet", [&] { verbosity = 1; }, "Stage lines and summaries only, no progress bars");
  app.add_flag_callback(
      "--silent", [&] { verbosity = 0; }, "Errors only");
  app.add_option("--threads", threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);

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
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and a pointer to --help
    return ibrdf::kUsageErrorExitCode;
  } catch (const ibrdf::Error& e) {
    std::cerr << "ibrdf: error: " << e.what() << std::endl;
    return 1;
  } catch (const ibrdf::InternalError& e) {
    std::cerr << "ibrdf: bug: " << e.what() << " (please report it)" << std::endl;
    return 70;
  } catch (const std::exception& e) {
    std::cerr << "ibrdf: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
