// The report stage: the consistency report of an `ibrdf run` folder, one self-contained HTML file with
// PNG figures beside it, like the paper's summary figures. This library does what needs the session
// and the BRDF models (the measured photo, rendered spheres, the reconstruction and the truth along the
// incidence plane, written to report-data.json); scripts/report.py (matplotlib, report/report_script.h)
// draws the plots and writes the HTML. docs/report.md describes it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace ibrdf {

struct ReportOptions {
  int photo = -1;          // the measured photo shown beside the renders (negative: the one of median phase angle)
  int render_size = 256;   // pixels, square renders of a sphere, in [16, 4096]
  bool overwrite = false;  // replace an existing report folder
  std::string script;      // the plotting script (empty: FindReportScript())
  std::string python;      // the python3 that runs it (empty: ReportPython())
  // False with `*why` naming the failing constraint.
  bool Check(std::string* why) const;
};

// What the stage wrote; reads as failure until the folder was committed.
struct ReportResult {
  bool success = false;         // the report folder was committed
  std::string index_html;       // OUT/index.html
  size_t samples = 0;           // samples in the run folder
  uint32_t photo = 0;           // the photo shown (chosen or given)
  double phase_deg = 0.0;       // its median phase angle
  bool photo_shown = false;     // the measured photo was cropped into photo.png
  std::string photo_note;       // why it was not, when the samples' session could not be read
  bool reconstruction = false;  // the run has reconstruction/brdf.binary (render.png, curves)
  bool truth = false;           // the run's truth-comparison.json names a truth (render-truth.png, curves)
  // One line: where, which photo, what was rendered.
  std::string BriefReport() const;
};

// Writes the report of `run_dir` (samples.npy; optionally its sidecar, reconstruction/brdf.binary and
// truth-comparison.json) into `out_dir` (empty: RUN_DIR/report), atomically. Throws Error when
// run_dir is not a completed run folder, the script or python is missing, or the script fails.
ReportResult WriteReport(const std::string& run_dir, const ReportOptions& options, const std::string& out_dir = "");

}  // namespace ibrdf
