#include "workflow/snakemake_workflow.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "workflow/build_id.h"

namespace fs = std::filesystem;

namespace ibrdf {

std::string FindSnakemakeDir() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("IBRDF_SNAKEMAKE_DIR")) {
    candidates = {env};
  } else {
    const fs::path binary = ExecutablePath();
    candidates = {(binary.parent_path() / ".." / "share" / "ibrdf" / "snakemake").lexically_normal().string(),
                  IBRDF_SOURCE_SNAKEMAKE_DIR};
  }
  std::string tried;
  for (const std::string& dir : candidates) {
    if (fs::is_regular_file(fs::path(dir) / "Snakefile")) return fs::absolute(dir).lexically_normal().string();
    tried += (tried.empty() ? "" : ", ") + dir;
  }
  ThrowError("ibrdf batch", "no Snakefile found (looked in " + tried + "; set IBRDF_SNAKEMAKE_DIR)");
}

std::string FindSnakemake() {
  if (const char* env = std::getenv("IBRDF_SNAKEMAKE")) return env;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / "snakemake";
    if (access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return candidate.string();
  }
  ThrowError("ibrdf batch",
             "snakemake is not installed (not on PATH): scripts/install-deps installs Debian's "
             "package (apt-get install snakemake)");
}

bool SnakemakeRunOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!snakemake.empty());
  IBRDF_CHECK_OPTION(!snakemake_dir.empty());
  IBRDF_CHECK_OPTION(!config.empty());
  IBRDF_CHECK_OPTION(!out_dir.empty());
  IBRDF_CHECK_OPTION(!ibrdf.empty());
  IBRDF_CHECK_OPTION_GE(cores, 0);
  return true;
}

std::vector<std::string> SnakemakeArguments(const SnakemakeRunOptions& o) {
  std::string why;
  if (!o.Check(&why)) ThrowError("ibrdf batch", why);
  std::vector<std::string> argv = {
      o.snakemake,         "--snakefile",      (fs::path(o.snakemake_dir) / "Snakefile").string(),
      "--directory",       o.out_dir,          "--config",
      "batch=" + o.config, "ibrdf=" + o.ibrdf, "--keep-going",
      "--rerun-incomplete"};
  // Which sessions run is ibrdf's decision (the plan); Snakemake's other triggers (a changed set of
  // inputs, params, code) would rebuild the library on the call after every retry.
  argv.insert(argv.end(), {"--rerun-triggers", "mtime"});
  if (!o.profile.empty()) {
    const std::string profile =
        o.profile == "slurm" ? (fs::path(o.snakemake_dir) / "profiles" / "slurm").string() : o.profile;
    argv.insert(argv.end(), {"--profile", fs::absolute(profile).string()});
  }
  if (o.profile.empty() || o.cores > 0) {
    argv.insert(argv.end(), {"--cores", o.cores > 0 ? std::to_string(o.cores) : "all"});
  } else if (o.dry_run) {
    // A dry run caps every job's threads at --cores (1 when absent); a cluster run does not.
    argv.insert(argv.end(), {"--cores", "1024"});
  }
  if (o.dry_run) argv.insert(argv.end(), {"--dry-run", "--printshellcmds"});
  if (o.quiet && !o.dry_run) argv.insert(argv.end(), {"--quiet", "progress"});
  argv.insert(argv.end(), o.extra.begin(), o.extra.end());
  return argv;
}

}  // namespace ibrdf
