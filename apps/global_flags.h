// The global flags of the ibrdf tool (-q/--quiet, --silent, --threads N, --version), accepted before or
// after the subcommand: the front end (apps/main.cc) reads them to find the subcommand, and every
// subcommand's binary (apps/command_main.cc) reads them again wherever they are. Header-only, so that the
// front end links nothing.
#pragma once

#include <CLI/CLI.hpp>

namespace ibrdf {

// The tool's description and its global flags on `app`, which takes exactly one subcommand.
// `verbosity`: 2 (progress bars), 1 (-q: stage lines and summaries), 0 (--silent: errors only);
// `threads`: 0 for all cores.
inline void AddGlobalFlags(CLI::App& app, int& verbosity, int& threads) {
  app.description(
      "ibrdf: image-based BRDF measurement (after Marschner et al. 1999).\n"
      "Photograph a curved sample under one small light from many positions; every pixel is a BRDF sample.");
  app.require_subcommand(1);
  app.set_version_flag("--version", "ibrdf " IBRDF_VERSION);
  app.add_flag_callback(
      "-q,--quiet", [&verbosity] { verbosity = 1; }, "Stage lines and summaries only, no progress bars");
  app.add_flag_callback(
      "--silent", [&verbosity] { verbosity = 0; }, "Errors only");
  app.add_option("--threads", threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
}

}  // namespace ibrdf
