// The subcommands of the ibrdf tool. Each subcommand lives in its own apps/<name>_command.cc,
// defines and registers itself with IBRDF_COMMAND and is built into its own binary `ibrdf-<name>` by one
// line of apps/CMakeLists.txt (ibrdf_add_command; IBRDF_COMMAND below says how to add one).
// Library code never sees argv. The helpers below bind the flags several subcommands share.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/logging.h"       // Log, StageLog: what every command prints
#include "core/output_guard.h"  // RequireWritableOutput: every command's output guard

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

// An option whose default --help shows.
template <typename T>
CLI::Option* AddOption(CLI::App& app, const std::string& name, T& value, const std::string& help) {
  return app.add_option(name, value, help)->capture_default_str();
}

// --out (required) and --overwrite, the flags of a command that writes one output.
void AddOutputFlags(CLI::App& app, std::string& out, bool& overwrite, const std::string& out_help,
                    const std::string& overwrite_help);

// A flag that sets `value` to false (--no-fits clears `fits`). Not CLI11's negated flag ("!--no-fits"),
// which --help shows as "--no-fits{false}".
CLI::Option* AddClearingFlag(CLI::App& app, const std::string& name, bool& value, const std::string& help);

// A length kept in metres and given in millimetres (--marker-mm); --help shows its default in millimetres.
CLI::Option* AddMillimetres(CLI::App& app, const std::string& name, double& metres, const std::string& help);

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

// An option with a default shown (AddOption) and its deprecated former name (AddDeprecatedAlias).
template <typename T>
CLI::Option* AddRenamedOption(CLI::App& app, const std::string& name, const std::string& old_name, T& value,
                              const std::string& help) {
  CLI::Option* option = AddOption(app, name, value, help);
  AddDeprecatedAlias(app, option, old_name, value);
  return option;
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

// Defines the subcommand function `Add<Name>Command(CLI::App& app)` (its body follows) and registers it.
// A new subcommand `foo`: apps/foo_command.cc holds `IBRDF_COMMAND(95, Foo) { app.add_subcommand("foo", ...) ...
// }`, and apps/CMakeLists.txt `ibrdf_add_command(foo 95 "one-line summary" ibrdf_x ...)` naming the
// libraries it calls (95: its place in `ibrdf --help`); configuring fails without that line.
#define IBRDF_COMMAND(order, Name)                   \
  static void Add##Name##Command(CLI::App& app);     \
  IBRDF_REGISTER_COMMAND(order, Add##Name##Command); \
  static void Add##Name##Command(CLI::App& app)
