// Runs another program as a child process of this one (the stages of `ibrdf run`, the report's Python
// plotting script), with the child's output going straight to this process's stdout and stderr.
#pragma once

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"

namespace ibrdf {

// Runs argv[0] (a path) with `argv`; the child is killed if this process dies. Returns the child's exit
// code, or 128 + the signal that killed it. Test hook: when the environment variable
// IBRDF_RUN_INTERRUPT equals `hook_name`, the child is killed with SIGKILL after
// IBRDF_RUN_INTERRUPT_AFTER_S seconds (default 0.05), as an interruption would.
inline int RunChildProcess(const std::vector<std::string>& argv, const std::string& hook_name = "") {
  IBRDF_CHECK(!argv.empty());
  std::vector<char*> raw;
  for (const std::string& arg : argv) raw.push_back(const_cast<char*>(arg.c_str()));
  raw.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  IBRDF_CHECK(pid >= 0) << "fork failed";
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  const char* interrupt = std::getenv("IBRDF_RUN_INTERRUPT");
  if (interrupt && !hook_name.empty() && hook_name == interrupt) {
    const char* after = std::getenv("IBRDF_RUN_INTERRUPT_AFTER_S");
    std::this_thread::sleep_for(std::chrono::duration<double>(after ? std::atof(after) : 0.05));
    ::kill(pid, SIGKILL);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    IBRDF_CHECK(errno == EINTR) << "waitpid failed";
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

}  // namespace ibrdf
