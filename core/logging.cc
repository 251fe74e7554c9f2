#include "core/logging.h"

#include <unistd.h>

#include <cstdio>
#include <exception>
#include <iostream>
#include <sstream>

#include "core/progress_observer.h"

namespace ibrdf {
namespace {
std::atomic<int> g_verbosity{2};
ProgressObserver g_progress_observer;
}

void SetProgressObserver(ProgressObserver observer) { g_progress_observer = std::move(observer); }

void SetVerbosity(int level) { g_verbosity = level; }
int Verbosity() { return g_verbosity; }

void Log(int level, const std::string& line) {
  if (g_verbosity >= level) std::cerr << line << std::endl;
}

StageLog::StageLog(std::string name) : name_(std::move(name)), exceptions_(std::uncaught_exceptions()) {
  Log(1, "== " + name_);
}

StageLog::~StageLog() {
  if (std::uncaught_exceptions() > exceptions_) return;  // failed: no timer before the error line
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.2f s", timer_.ElapsedSeconds());
  Log(1, "-- " + name_ + ": " + buffer);
}

ProgressBar::ProgressBar(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total), tty_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Add(uint64_t done) {
  const uint64_t now = done_.fetch_add(done) + done;
  if (g_progress_observer && !g_progress_observer(label_, now, total_)) {
    throw Interrupted(label_ + ": interrupted");
  }
  if (g_verbosity < 2) return;
  const double t = timer_.ElapsedSeconds();
  const int quarter = total_ ? static_cast<int>(4 * now / total_) : 4;
  if (tty_ ? (t - last_draw_s_ >= 0.2) : (quarter > last_quarter_)) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    if (tty_ ? (t - last_draw_s_ >= 0.2) : (quarter > last_quarter_)) {
      last_draw_s_ = t;
      last_quarter_ = quarter;
      Draw(now, false);
    }
  }
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (g_verbosity >= 2 && tty_) Draw(done_, true);
}

void ProgressBar::Draw(uint64_t done, bool final) {
  const double fraction = total_ ? static_cast<double>(done) / total_ : 1.0;
  const int width = 30;
  const int filled = static_cast<int>(fraction * width + 0.5);
  std::ostringstream line;
  line << "   " << label_ << " [" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << done << "/"
       << total_;
  char seconds[32];
  const double elapsed = timer_.ElapsedSeconds();
  std::snprintf(seconds, sizeof(seconds), " %.1f s", elapsed);
  line << seconds;
  if (!final && done > 0 && done < total_) {  // the time estimate: the rate so far, extrapolated
    std::snprintf(seconds, sizeof(seconds), ", about %.0f s left", elapsed * double(total_ - done) / double(done));
    line << seconds;
  }
  if (tty_) {
    std::cerr << "\r" << line.str() << (final ? "\n" : "") << std::flush;
  } else {
    std::cerr << line.str() << "\n";
  }
}

std::string Fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, value);
  return buffer;
}

std::string FormatCounts(const RejectionCounts& counts) {
  std::ostringstream out;
  bool first = true;
  for (const auto& [reason, count] : counts) {
    if (count == 0) continue;
    out << (first ? "" : ", ") << reason << " " << count;
    first = false;
  }
  return first ? "none" : out.str();
}

}  // namespace ibrdf
