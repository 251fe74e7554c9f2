// Runs the ibrdf binary as a user would, for the command-line tests.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace ibrdf::testing {

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command and collects its standard output (append " 2>&1" for standard error too) and exit code.
inline RunResult RunShell(const std::string& command) {
  RunResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs `ibrdf --silent ARGUMENTS` (or `-q` when `quiet`, which keeps stage summaries) and collects
// its output and exit code.
inline RunResult RunIbrdf(const std::string& arguments, bool quiet = false) {
  return RunShell(std::string(IBRDF_BINARY) + (quiet ? " -q " : " --silent ") + arguments + " 2>&1");
}

}  // namespace ibrdf::testing
