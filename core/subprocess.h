// Runs another program as a child process (the stages of `ibrdf run`, the report's plotting script,
// COLMAP): the one launcher of the tool. The child dies with this process (PR_SET_PDEATHSIG).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace ibrdf {

struct SubprocessOptions {
  // File that receives the child's stdout and stderr (created or truncated); empty: the child writes
  // to this process's stdout and stderr.
  std::string log_path;
  // Variables set in the child's environment (name, value), on top of this process's.
  std::vector<std::pair<std::string, std::string>> environment;
  // Test hook: when the environment variable IBRDF_RUN_INTERRUPT equals this (non-empty) name, the
  // child is killed with SIGKILL after IBRDF_RUN_INTERRUPT_AFTER_S seconds (default 0.05), as an
  // interruption would.
  std::string interrupt_hook;
};

// Runs argv[0] (a path, not searched on PATH) with `argv`. Returns the child's exit code, 128 + the
// signal that killed it, 126 if the log file could not be opened, 127 if argv[0] could not be run.
int RunSubprocess(const std::vector<std::string>& argv, const SubprocessOptions& options = {});

}  // namespace ibrdf
