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

// The running tool's identity. Started through the `ibrdf` front end (IBRDF_TOOL set, apps/main.cc):
// one hash over the build ids of the front end and every ibrdf-<name> binary beside it, so that
// rebuilding any subcommand changes it. Otherwise ElfBuildId("/proc/self/exe"), or FileContentHash of
// it when it has no build-id note. Computed once per process.
std::string ExecutableBuildId();

// How to run the tool again (a stage's child process): the front end that started this process
// (IBRDF_TOOL), else the running binary's path (/proc/self/exe resolved); throws InternalError when it
// cannot be read.
std::string ExecutablePath();

}  // namespace ibrdf
