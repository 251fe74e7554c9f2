// Stage headings, timers, progress bars and rejection counters (pbrt's STAT_* in spirit).
// Everything prints to stderr so that stdout stays free for machine-readable output.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace ibrdf {

// Global verbosity: 0 = errors only (tests), 1 = stage lines and summaries, 2 = progress bars too.
void SetVerbosity(int level);
int Verbosity();

// Prints one line to stderr when the verbosity is at least `level`.
void Log(int level, const std::string& line);

// Wall-clock stopwatch.
class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  void Restart() { start_ = std::chrono::steady_clock::now(); }
  double ElapsedSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// A stage heading on construction ("== derender") and a timing line on destruction
// ("-- derender: 1.23 s"), left out when the stage ends by an exception (the error line follows).
class StageLog {
 public:
  explicit StageLog(std::string name);
  ~StageLog();
  double ElapsedSeconds() const { return timer_.ElapsedSeconds(); }

 private:
  std::string name_;
  Timer timer_;
  int exceptions_ = 0;  // std::uncaught_exceptions() at construction
};

// A thread-safe progress bar over a known number of work items. Redraws at most every 0.2 s, on a
// terminal only; elsewhere (CI logs) it prints one line per 25 %.
class ProgressBar {
 public:
  ProgressBar(std::string label, uint64_t total);
  ~ProgressBar();
  void Add(uint64_t done);
  void Finish();

 private:
  void Draw(uint64_t done, bool final);

  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::mutex mutex_;
  Timer timer_;
  double last_draw_s_ = -1.0;
  int last_quarter_ = 0;
  bool finished_ = false;
  bool tty_ = false;
};

// Counts of rejected items by reason ("saturated", "grazing_incidence" ...), kept in a stable order.
using RejectionCounts = std::map<std::string, uint64_t>;

// "saturated 12, grazing_incidence 3" (reasons with a zero count are left out).
std::string FormatCounts(const RejectionCounts& counts);

// `value` with `digits` decimals ("%.*f"): the figures of a stage's messages.
std::string Fixed(double value, int digits);

}  // namespace ibrdf
