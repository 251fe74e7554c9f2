// The subcommands of the ibrdf tool. Each subcommand lives in its own apps/<name>_command.cc,
// registers itself with IBRDF_REGISTER_COMMAND and is built into its own binary `ibrdf-<name>` by one
// line of apps/CMakeLists.txt (ibrdf_add_command; apps/main.cc, the front end, says how to add one).
// Library code never sees argv.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace ibrdf {

using AddCommandFunction = void (*)(CLI::App& app);

// The exit status of a usage error (an unknown option or subcommand, a missing or malformed argument).
constexpr int kUsageErrorExitCode = 2;

// Registers a subcommand at static-initialization time; `order` sets its place among the subcommands
// of one binary (the workflow's order: synth 10, scan 20, align 30, derender 40, reconstruct 50,
// check 60, report 70, run 80, compare 90; the front end's listing takes it from apps/CMakeLists.txt).
struct CommandRegistrar {
  CommandRegistrar(int order, AddCommandFunction add);
};

// The registered subcommands, sorted by order.
std::vector<AddCommandFunction> RegisteredCommands();

// Throws Error unless `output` may be written: it must not be one of the stage's inputs, and an
// existing file is replaced only with --overwrite.
void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs);

}  // namespace ibrdf

#define IBRDF_REGISTER_COMMAND(order, function) \
  static const ::ibrdf::CommandRegistrar function##_registrar(order, &function)
