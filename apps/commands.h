// The subcommands of the ibrdf tool. Each Add*Command registers its options on the CLI11 app and sets
// the callback that runs it; library code never sees argv.
#pragma once

#include <CLI/CLI.hpp>

namespace ibrdf {

void AddSynthCommand(CLI::App& app);
void AddDerenderCommand(CLI::App& app);
void AddCheckCommand(CLI::App& app);
void AddCompareCommand(CLI::App& app);

// Throws Error unless `output` may be written: it must not be one of the stage's inputs, and an
// existing file is replaced only with --overwrite.
void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs);

}  // namespace ibrdf
