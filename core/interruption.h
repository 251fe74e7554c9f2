// Interrupted runs leave no temporaries behind: on SIGINT, SIGTERM or SIGHUP the process removes every
// temporary file and folder an AtomicFile or AtomicDirectory (core/file_util.h) still holds, then ends
// by the same signal, so its exit status is the one the signal would have given. A process killed
// outright (SIGKILL) cannot clean up; the next writer of the same output removes its leftovers
// (RemoveStaleTemporariesOf).
#pragma once

#include <string>

namespace ibrdf {

// Installs the handlers (once; later calls do nothing). A signal the process inherited as ignored
// (a background job's SIGINT, nohup's SIGHUP) stays ignored. The main() of every binary calls it first.
void RemoveTemporariesOnInterrupt();

// The temporaries the handler removes: AtomicFile and AtomicDirectory add theirs while they hold one.
void RegisterTemporary(const std::string& path);
void UnregisterTemporary(const std::string& path);

}  // namespace ibrdf
