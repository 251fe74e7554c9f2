// The identity of a built binary: the key of `ibrdf run`'s stamps, so that a rebuilt binary re-runs
// every stage even when its version string is unchanged (docs/workflow.md).
#pragma once

#include <string>

namespace ibrdf {

// The GNU build-id note of a 64-bit ELF file as "gnu-build-id:<hex>" (the linker's hash of the linked
// output; CMake links with --build-id, workflow/CMakeLists.txt), or "" when the file is not such an
// ELF file or has no note. Throws Error naming the file when it cannot be read.
std::string ElfBuildId(const std::string& path);

// A hash of the file's bytes, "fnv1a64:<hex>"; throws Error naming the file when it cannot be read.
std::string FileContentHash(const std::string& path);

// The running binary's identity: ElfBuildId("/proc/self/exe"), or FileContentHash of it when it has no
// build-id note. Computed once per process.
std::string ExecutableBuildId();

// The running binary's path (/proc/self/exe resolved); throws InternalError when it cannot be read.
std::string ExecutablePath();

}  // namespace ibrdf
