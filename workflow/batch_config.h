// A batch of measurements (`ibrdf batch CONFIG`, the Snakemake workflow of snakemake/Snakefile): a JSON
// file naming session folders, recipes or glob patterns of them, the run options, and the folder
// that receives one run folder per session, one log per session and the material library
// (docs/workflow.md, "Batches").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "workflow/measurement.h"

namespace ibrdf {

// One measurement of a batch: `ibrdf run INPUT --out RUN_DIR <options>` with its output in LOG_PATH.
struct BatchEntry {
  std::string name;            // unique in the batch: [A-Za-z0-9._-], names the run folder and the log
  std::string input;           // the session folder, session.json, recipe folder or recipe.json (absolute)
  std::string run_dir;         // OUT/runs/<name>
  std::string log_path;        // OUT/logs/<name>.log: the job's stdout and stderr
  MeasurementOptions options;  // the batch's options with the entry's own on top
};

struct BatchConfig {
  std::string path;                  // the config file (absolute)
  std::string out_dir;               // the batch folder (absolute): runs/, logs/, library/
  int threads_per_job = 1;           // --threads of each `ibrdf run`; the cores a cluster job asks for
  int mem_mb_per_job = 4000;         // memory a cluster job asks for (Slurm --mem), MB
  int runtime_min_per_job = 60;      // time a cluster job asks for (Slurm --time), minutes
  std::vector<std::string> compare;  // materials in the library's comparison plot (empty: the first 8)
  std::vector<BatchEntry> entries;   // in the order of the config, glob matches sorted

  // OUT/library.
  std::string LibraryDir() const;
};

// Reads and checks a batch config:
//   {"format": "ibrdf-batch", "version": 1,
//    "out": "batch-out",                          relative to the config file
//    "sessions": ["sessions/*", "../samples/felt-sphere", {"path": "p", "name": "n", "options": {...}}],
//    "options": {"stride": 2, "fits": true, "report": true, "check_regression": false,
//                "degree": 1, "radius_h_deg": 3, "radius_d_deg": 6, "align_args": "--max-rms-px 2", ...},
//    "threads_per_job": 1, "mem_mb_per_job": 4000, "runtime_min_per_job": 60,
//    "compare": ["bluepaint", "felt"]}
// A session entry is a session folder, a session.json, a recipe folder or a recipe.json, or a glob
// pattern (*, ?, [..]) matching such folders; paths are relative to the config file. Errors name the
// file and the field: unknown keys, a path that does not exist, a pattern that matches nothing, two
// entries with one name (give them "name"), a name with other characters than [A-Za-z0-9._-].
// The sessions themselves are not opened here: a broken one fails its own job, not the batch.
BatchConfig ReadBatchConfig(const std::string& path);

// The `ibrdf run` command line of an entry, after the program and its global flags:
// {"run", input, "--out", run_dir, "--stride", "2", ...} (only the options that differ from run's
// defaults).
std::vector<std::string> RunArguments(const BatchEntry& entry);

}  // namespace ibrdf
