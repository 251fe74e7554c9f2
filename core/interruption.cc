#include "core/interruption.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

namespace ibrdf {
namespace {

constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};

std::mutex& RegistryMutex() {
  static std::mutex mutex;
  return mutex;
}

std::set<std::string>& Registry() {
  static std::set<std::string> paths;
  return paths;
}

// The handler only writes the signal's number to this pipe (write is async-signal-safe); the cleanup
// thread reads it and does the work a handler may not (locks, allocation, file-system walks).
int signal_pipe[2] = {-1, -1};
pid_t owner = 0;

void OnSignal(int signal_number) {
  if (::getpid() != owner) {  // a forked child before its exec: die as it would have
    ::signal(signal_number, SIG_DFL);
    ::raise(signal_number);
    return;
  }
  const unsigned char byte = static_cast<unsigned char>(signal_number);
  const ssize_t written = ::write(signal_pipe[1], &byte, 1);
  (void)written;
}

void CleanUpOnSignal() {
  unsigned char byte = 0;
  for (;;) {
    const ssize_t n = ::read(signal_pipe[0], &byte, 1);
    if (n == 1) break;
    if (n < 0 && errno == EINTR) continue;
    return;
  }
  const int signal_number = byte;
  // Held until the end: no new temporary appears while the process goes.
  std::lock_guard<std::mutex> lock(RegistryMutex());
  for (const std::string& path : Registry()) {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  ::signal(signal_number, SIG_DFL);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, signal_number);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(signal_number);
  ::_exit(128 + signal_number);  // only if the default action did not end the process
}

}  // namespace

void RemoveTemporariesOnInterrupt() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (::pipe2(signal_pipe, O_CLOEXEC) != 0) return;
    owner = ::getpid();
    std::thread(CleanUpOnSignal).detach();
    for (const int signal_number : kSignals) {
      struct sigaction previous {};
      if (::sigaction(signal_number, nullptr, &previous) != 0 || previous.sa_handler == SIG_IGN) continue;
      struct sigaction action {};
      action.sa_handler = OnSignal;
      sigemptyset(&action.sa_mask);
      action.sa_flags = SA_RESTART;
      ::sigaction(signal_number, &action, nullptr);
    }
  });
}

void RegisterTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry().insert(path);
}

void UnregisterTemporary(const std::string& path) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry().erase(path);
}

}  // namespace ibrdf
