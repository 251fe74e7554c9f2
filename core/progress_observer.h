// A watcher of every progress bar (core/logging.h ProgressBar), for a caller that reports progress
// itself or stops long work: the Python module's progress callback and its Ctrl-C check (python/).
// Kept apart from logging.h so that the stages, which only advance bars, do not see it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/error.h"

namespace ibrdf {

// Called on the thread that advanced a bar (possibly several at once) with the bar's label, the items
// done and the total; returning false stops the work: ProgressBar::Add throws Interrupted, which the
// stage's parallel loops pass on to the stage's caller. It must be cheap and thread-safe.
using ProgressObserver = std::function<bool(const std::string& label, uint64_t done, uint64_t total)>;

// Installs `observer` for every progress bar of the process (an empty one: none, the default). Set it
// only while no stage runs.
void SetProgressObserver(ProgressObserver observer);

// Work stopped by a progress observer before it ended; no output was committed.
class Interrupted : public Error {
 public:
  using Error::Error;
};

}  // namespace ibrdf
