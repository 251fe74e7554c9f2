#include "core/subprocess.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <thread>

#include "core/error.h"

namespace ibrdf {

int RunSubprocess(const std::vector<std::string>& argv, const SubprocessOptions& options) {
  IBRDF_CHECK(!argv.empty());
  // Everything the child needs is prepared before fork: only async-signal-safe calls after it.
  std::vector<std::string> args = argv;
  std::vector<char*> raw;
  for (std::string& arg : args) raw.push_back(arg.data());
  raw.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  IBRDF_CHECK(pid >= 0) << "fork failed";
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    if (!options.log_path.empty()) {
      const int log = ::open(options.log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (log < 0) ::_exit(126);
      ::dup2(log, STDOUT_FILENO);
      ::dup2(log, STDERR_FILENO);
      ::close(log);
    }
    for (const auto& [name, value] : options.environment) ::setenv(name.c_str(), value.c_str(), 1);
    ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  const char* interrupt = std::getenv("IBRDF_RUN_INTERRUPT");
  if (interrupt && !options.interrupt_hook.empty() && options.interrupt_hook == interrupt) {
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
