// The main() of each subcommand's binary `ibrdf-<name>` (apps/CMakeLists.txt, ibrdf_add_command): the
// front end (apps/main.cc) execs it with the whole command line. It parses the global flags wherever
// they are (the subcommand falls through to them), runs the one subcommand linked in, and maps
// failures to exit codes: 2 for a usage error, 1 for an error in the input, 70 for a bug.
// Also the subcommand registry and the flag helpers of apps/commands.h.
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/global_flags.h"
#include "core/error.h"
#include "core/interruption.h"
#include "core/logging.h"

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

namespace {

// The subcommand the command line selected ("" before one was recognized).
std::string StageName(CLI::App& app) {
  const std::vector<CLI::App*> selected = app.get_subcommands();
  return selected.empty() ? "" : selected.front()->get_name();
}

// "ibrdf: error: derender: " and the message.
void PrintUsageError(CLI::App& app, const std::string& message) {
  const std::string stage = StageName(app);
  std::cerr << "ibrdf: error: " << (stage.empty() ? "" : stage + ": ") << message << "\n"
            << "Run with --help for more information." << std::endl;
}

// Check()'s constraint with each options field named by the stage's flag that sets it: a field is the
// flag's long name with '_' for '-' (max_theta_i_deg: --max-theta-i-deg), or ends or starts with it as a
// word (pixel_stride: --stride, held_out_photos: --held-out); the longest such flag wins. Fields no flag
// sets keep their names.
std::string WithFlagNames(CLI::App& app, const std::string& why) {
  std::vector<std::string> flags;
  for (CLI::App* stage : app.get_subcommands()) {
    for (const CLI::Option* option : stage->get_options()) {
      for (const std::string& name : option->get_lnames()) flags.push_back(name);
    }
  }
  auto flag_of = [&flags](const std::string& field) {
    const size_t dot = field.rfind('.');
    const std::string leaf = dot == std::string::npos ? field : field.substr(dot + 1);
    std::string best;
    for (const std::string& name : flags) {
      std::string key = name;
      for (char& c : key) c = c == '-' ? '_' : c;
      const bool ends = leaf.size() > key.size() && leaf.compare(leaf.size() - key.size(), key.size(), key) == 0 &&
                        leaf[leaf.size() - key.size() - 1] == '_';
      const bool starts = leaf.size() > key.size() && leaf.compare(0, key.size(), key) == 0 && leaf[key.size()] == '_';
      if ((leaf == key || (key.size() >= 3 && (ends || starts))) && key.size() > best.size()) best = name;
    }
    return best.empty() ? field : "--" + best;
  };
  std::string out;
  for (size_t i = 0; i < why.size();) {
    const unsigned char c = static_cast<unsigned char>(why[i]);
    if (!std::islower(c)) {
      out += why[i++];
      continue;
    }
    size_t end = i;
    while (end < why.size() && (std::isalnum(static_cast<unsigned char>(why[end])) || why[end] == '_' ||
                                why[end] == '.')) {
      ++end;
    }
    const std::string word = why.substr(i, end - i);
    const bool field = word.find('_') != std::string::npos || word.find('.') != std::string::npos;
    const std::string flag = flag_of(word);
    out += field || flag != word ? flag : word;
    i = end;
  }
  return out;
}

// The arguments CLI11 did not expect, in the order given (its message lists them last to first).
std::string ExtrasInOrder(CLI::App& app, int argc, char** argv) {
  const std::vector<std::string> remaining = app.remaining(true);
  std::multiset<std::string> left(remaining.begin(), remaining.end());
  std::string ordered;
  for (int i = 1; i < argc; ++i) {
    const auto it = left.find(argv[i]);
    if (it == left.end()) continue;
    ordered += (ordered.empty() ? "" : " ") + std::string(argv[i]);
    left.erase(it);
  }
  return ordered;
}

}  // namespace

int main(int argc, char** argv) {
  ibrdf::RemoveTemporariesOnInterrupt();
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
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const ibrdf::OptionValueError& e) {
    // The flags the command named ("--fill"), unless it named only itself ("ibrdf derender").
    const std::string what = e.what();
    const std::string flags = what.substr(0, what.find(": bad value: "));
    const bool named_flags = flags.rfind("ibrdf ", 0) != 0 && flags != what;
    PrintUsageError(app, (named_flags ? flags + ": " : "") + "bad value: " + WithFlagNames(app, e.why()));
    return ibrdf::kUsageErrorExitCode;
  } catch (const CLI::ExtrasError& e) {
    const std::string extras = ExtrasInOrder(app, argc, argv);
    PrintUsageError(app, extras.empty() ? std::string(e.what()) : "unexpected arguments: " + extras);
    return ibrdf::kUsageErrorExitCode;
  } catch (const CLI::RuntimeError& e) {
    // A command that has said why it stops (`session init` on an incomplete draft) and asks for this
    // exit code: no second message.
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    PrintUsageError(app, e.what());
    return ibrdf::kUsageErrorExitCode;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the file system refused (a symlink loop, a permission): named, with the system's reason.
    std::cerr << "ibrdf: error: " << (e.path1().empty() ? std::string() : e.path1().string() + ": ")
              << e.code().message() << std::endl;
    return 1;
  } catch (const ibrdf::Error& e) {
    std::cerr << "ibrdf: error: " << e.what() << std::endl;
    return 1;
  } catch (const ibrdf::InternalError& e) {
    std::cerr << "ibrdf: bug: " << e.what() << " (please report it)" << std::endl;
    return 70;
  } catch (const std::exception& e) {  // ibrdf::Error (bad input) and every other failure
    std::cerr << "ibrdf: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
