// The material library (`ibrdf library`): finished runs collected into one folder, each material's
// MERL table, fits, renderer snippets and .bsdf under its name, a lit sphere per material, an
// index.json with each run's figures (or its error) and an index.html gallery with a comparison plot of
// selected materials in the incidence plane (docs/workflow.md, "The material library").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace ibrdf {

// One run to collect.
struct LibraryEntry {
  std::string name;      // the material's name in the library ([A-Za-z0-9._-])
  std::string run_dir;   // the `ibrdf run` folder
  std::string source;    // the session or recipe it measured ("" : read from the run's summary.json)
  std::string log_path;  // the job's log (batches), read for the error of a failed run; "" : none
};

struct LibraryOptions {
  std::string out_dir;               // the library folder; written whole and renamed into place
  std::vector<std::string> compare;  // materials in the comparison plot (empty: the first 8 collected)
  int sphere_size = 160;             // lit sphere images, pixels
  double sphere_phase_deg = 30.0;    // the light's angle from the view direction
  // The sphere's exposure: the radiance of a white Lambertian disc facing the light (1/pi) maps to
  // this fraction of full scale; one exposure for every material, so the gallery compares albedos.
  double sphere_white_level = 0.8;
  bool overwrite = false;  // replace an existing folder that is not an ibrdf library

  bool Check(std::string* why) const;
};

struct LibraryResult {
  bool success = false;                // the library was written (some runs may still have failed)
  int materials = 0;                   // runs collected
  int failed = 0;                      // runs whose log ends with an error
  int incomplete = 0;                  // runs with no summary.json and no error in a log (never run, or interrupted)
  std::string index_json, index_html;  // the written files
  double seconds = 0.0;

  // "6 materials, 1 failed, 0 incomplete: /lib/index.html (2.1 s)".
  std::string BriefReport() const;
};

// Collects `entries` into options.out_dir (replaced as a whole; an existing folder that is not an
// ibrdf library is replaced only with `overwrite`). Optional files a run may lack (fits, snippets,
// .bsdf, the report, figures of synthetic sessions) are listed as absent, not errors. Throws Error for
// invalid options, two entries with one name, or an out_dir inside a run folder or holding one.
LibraryResult BuildLibrary(const std::vector<LibraryEntry>& entries, const LibraryOptions& options);

// The entries of `ibrdf run` folders, each material named after its folder. Throws Error naming a run
// that is not a folder, or that is a session or recipe folder (a session.json or recipe.json and no
// run outputs: summary.json, reconstruction/).
std::vector<LibraryEntry> LibraryEntriesOfRuns(const std::vector<std::string>& run_dirs);

// The entry's state as the index records it: {"name", "status": "ok" | "failed" | "incomplete",
// "error", "log", "run_dir", "source", ...figures}. Exposed for the tests.
nlohmann::json LibraryRecord(const LibraryEntry& entry);

}  // namespace ibrdf
