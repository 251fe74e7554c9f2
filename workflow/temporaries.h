// Leftovers of an interrupted stage: every stage writes its outputs under hidden temporary names,
// ".NAME.tmp-PID-N" (core/file_util.h), and renames them when complete; a writer killed mid-way
// leaves its temporary behind.
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

// Removes the temporaries in `run_dir` and its direct (non-hidden) subfolders whose writer process no
// longer exists; those of a live process are kept. Returns the paths removed (each also logged).
std::vector<std::string> RemoveStaleTemporaries(const std::string& run_dir);

}  // namespace ibrdf
