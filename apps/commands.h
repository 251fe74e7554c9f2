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

// The output guard of every subcommand: throws Error unless `output` (a file or a folder the command
// writes or replaces) may be written. It must not be one of the command's inputs, nor a folder that
// holds one (symlinks resolved), --overwrite or not; an existing output is replaced only with
// --overwrite; its parent folder must exist. `inputs`: every file the command reads (missing ones and
// "" are ignored), and every input folder.
void RequireWritableOutput(const std::string& output, bool overwrite, const std::vector<std::string>& inputs);

// A file a stage writes beside the output the user named (a sidecar <out>.json): `format` is the JSON
// "format" of the file the stage writes there, which marks an existing one as the stage's own.
struct CompanionFile {
  std::string path;
  std::string format;
};

// The output guard over every file a stage writes: RequireWritableOutput for `output` and for each
// companion; an existing companion is replaced only when it is the stage's own (its "format" is the
// companion's), --overwrite or not, since the user named only `output` (`--out mat` beside a material
// file mat.json, `--out s1/truth` beside a session's truth.json).
void RequireWritableOutputs(const std::string& output, const std::vector<CompanionFile>& companions, bool overwrite,
                            const std::vector<std::string>& inputs);

// The first half of RequireWritableOutput: `output` is no input and holds none (for `run`, whose folder
// is resumed rather than replaced).
void RequireOutputOutsideInputs(const std::string& output, const std::vector<std::string>& inputs);

// Every regular file under `folder`, recursively (none if it is not a folder): the inputs of a command
// that reads a whole folder (a run folder, a COLMAP model, a calibration folder).
std::vector<std::string> FilesUnder(const std::string& folder);

// Prints once that `old_name` is deprecated in favour of `new_name` (a warning on standard error).
void WarnDeprecatedOption(const std::string& old_name, const std::string& new_name);

// Adds `old_name` as a hidden alias of `option` (both set `variable`), kept for one release after a
// rename (e.g. --radius to --radius-m): not shown by --help, takes as many values as the option (and its
// delimiter), warns once when used, and excludes the new name.
template <typename T>
CLI::Option* AddDeprecatedAlias(CLI::App& app, CLI::Option* option, const std::string& old_name, T& variable) {
  const std::string new_name = option->get_name();
  // Values are checked once the whole line is parsed, so both names' counts are known here. (Not
  // CLI11's excludes(): it would print the hidden alias, nameless, in the new name's help.)
  return app.add_option(old_name, variable, "Deprecated name of " + new_name)
      ->group("")
      ->expected(option->get_expected_min(), option->get_expected_max())
      ->delimiter(option->get_delimiter())
      ->each([option, old_name, new_name](const std::string&) {
        if (option->count() > 0) throw CLI::ExcludesError(old_name, new_name + " (the same option; give one)");
        WarnDeprecatedOption(old_name, new_name);
      });
}

// The error of an option value that a library's options Check() rejected: a usage error (exit 2), its
// message naming the flags and the failed constraint.
class OptionValueError : public CLI::ValidationError {
 public:
  OptionValueError(const std::string& flags, const std::string& why)
      : CLI::ValidationError(flags, "bad value: " + why), why_(why) {}
  // The failed constraint as Check() wrote it, in the options' field names (main() names the flags).
  const std::string& why() const { return why_; }

 private:
  std::string why_;
};

// Throws OptionValueError (a usage error, exit 2) unless `options.Check()` passes; `flags` names the
// flags that set them, e.g. "--stride/--max-theta-i-deg".
template <typename Options>
void RequireValidOptions(const Options& options, const std::string& flags) {
  std::string why;
  if (!options.Check(&why)) throw OptionValueError(flags, why);
}

}  // namespace ibrdf

#define IBRDF_REGISTER_COMMAND(order, function) \
  static const ::ibrdf::CommandRegistrar function##_registrar(order, &function)
