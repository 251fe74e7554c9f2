// The Snakemake workflow shipped with ibrdf (snakemake/Snakefile and its profiles) and the snakemake
// command line `ibrdf batch` runs it with. The Snakefile is looked for next to the running binary, like
// the report's script (report/report_script.h):
//   1. $IBRDF_SNAKEMAKE_DIR, when set (used as given);
//   2. <dir of the binary>/../share/ibrdf/snakemake/ (the installed layout);
//   3. the source tree's snakemake/ (compiled in; the build tree runs from it).
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

// The folder holding Snakefile and profiles/; an Error listing the places searched when none has a
// Snakefile.
std::string FindSnakemakeDir();

// The snakemake program: $IBRDF_SNAKEMAKE when set, else the first `snakemake` on PATH; an Error
// saying how to install it when there is none.
std::string FindSnakemake();

struct SnakemakeRunOptions {
  std::string snakemake;           // the program (FindSnakemake())
  std::string snakemake_dir;       // FindSnakemakeDir()
  std::string config;              // the batch config (absolute)
  std::string out_dir;             // the batch folder: Snakemake's working directory (its .snakemake/)
  std::string ibrdf;               // the binary the jobs run (absolute)
  int cores = 0;                   // local cores (--cores); 0: all
  std::string profile;             // a profile folder ("" : none; "slurm": the shipped Slurm profile)
  bool dry_run = false;            // list the jobs (-n -p), run nothing
  bool quiet = false;              // Snakemake's --quiet (its progress only)
  std::vector<std::string> extra;  // more snakemake arguments, as given

  bool Check(std::string* why) const;
};

// The snakemake command line: --snakefile, --directory, --config batch=... ibrdf=..., --keep-going
// (a failed session fails its job alone), --rerun-incomplete, --rerun-triggers mtime (the plan decides
// which sessions run), and --cores or --profile.
std::vector<std::string> SnakemakeArguments(const SnakemakeRunOptions& options);

}  // namespace ibrdf
