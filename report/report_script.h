// The report's plotting script (scripts/report.py, matplotlib) and how it is found and run. The script
// is looked for next to the running binary, so that an installed ibrdf works without the source tree:
//   1. $IBRDF_REPORT_SCRIPT, when set (used as given);
//   2. <dir of the binary>/../share/ibrdf/report.py (the installed layout: bin/ibrdf, share/ibrdf/);
//   3. <dir of the binary>/report.py (the build tree: the build copies it beside apps/ibrdf);
//   4. the source tree's scripts/report.py (compiled in).
#pragma once

#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace ibrdf {

// What the lookup starts from.
struct ReportScriptSearch {
  std::optional<std::string> environment;  // $IBRDF_REPORT_SCRIPT, if set
  std::string binary_path;                 // the running binary (empty: steps 2 and 3 are skipped)
  std::string source_script;               // the source tree's scripts/report.py (empty: step 4 skipped)
};

// The search of this process: its environment, /proc/self/exe and the compiled-in source path.
ReportScriptSearch DefaultReportScriptSearch();

// The paths tried, in the order above (only the environment's when it is set).
std::vector<std::string> ReportScriptCandidates(const ReportScriptSearch& search);

// The first candidate that is a regular file; the environment's path whenever it is set (even if it
// does not exist, so that the caller's check names it). Throws Error listing the places searched when
// no candidate exists.
std::string FindReportScript(const ReportScriptSearch& search = DefaultReportScriptSearch());

// The python3 the script runs with: Debian's, with python3-numpy and python3-matplotlib (compiled in).
std::string ReportPython();

// Runs `python script RUN_DIR OUT_DIR` (core/subprocess.h; RUN_DIR made absolute) and checks that it
// wrote OUT_DIR/index.html. Throws Error naming the script when it fails.
void RunReportScript(const std::string& python, const std::string& script, const std::string& run_dir,
                     const std::string& out_dir);

// The plotting script started before the report's data is ready, so that it imports matplotlib and
// draws the figures that need only the run folder (coverage, pair figures, timings, truth bands) while
// the C++ part computes: `python script RUN_DIR OUT_DIR --data-later` on a thread of its own. The
// script then waits for OUT_DIR/report-data.json (written atomically) and draws the rest.
class BackgroundReportScript {
 public:
  BackgroundReportScript(const std::string& python, const std::string& script, const std::string& run_dir,
                         const std::string& out_dir);
  // Without Finish() (the C++ part failed): writes OUT_DIR/report-abort, on which the script stops
  // waiting and exits, and waits for it.
  ~BackgroundReportScript();
  BackgroundReportScript(const BackgroundReportScript&) = delete;
  BackgroundReportScript& operator=(const BackgroundReportScript&) = delete;

  // Call once OUT_DIR/report-data.json is written: waits for the script and checks it as
  // RunReportScript does (Error naming the script when it failed or wrote no index.html).
  void Finish();

 private:
  std::string script_;
  std::string out_dir_;
  int code_ = 0;
  bool finished_ = false;
  std::thread thread_;
};

}  // namespace ibrdf
