// The report stage: the consistency report of an `ibrdf run` folder, one self-contained HTML file with
// PNG figures beside it, like the paper's summary figures, and an offline explorer page
// (explorer.html, the data embedded). This library does what needs the session and the BRDF models:
// the measured photo beside renderings of the actual sample (report/photo_comparison.h), spheres, the
// models along the incidence plane evaluated at the samples' own positions, the explorer's grids (all
// in report-data.json and .npy files); scripts/report.py (matplotlib, report/report_script.h) draws the
// plots and writes the HTML. docs/report.md describes it.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ibrdf {

struct ReportOptions {
  int photo = -1;            // the measured photo shown (negative: the one of median phase angle)
  int render_size_px = 256;  // pixels, square renders of a sphere, in [16, 4096]
  std::vector<double> angles_deg = {15, 30, 45, 60};  // incidence-plane angles theta_0, 1 to 8 in [0, 85]
  // Photos shown held out, in [0, 16]: each rendered by the local regression fitted without it (the
  // photos `ibrdf check --regression --held-out N` holds out; 0: none). One regression fit each.
  int held_out_photos = 1;
  std::string reconstruction;  // the reconstruction folder or its brdf.binary (empty: RUN_DIR/reconstruction)
  std::string title;           // the report's title (empty: the recipe's or session's name)
  bool explorer = true;        // write explorer.html
  bool overwrite = false;      // replace an existing report folder
  std::string script;          // the plotting script (empty: FindReportScript())
  std::string python;          // the python3 that runs it (empty: ReportPython())
  // False with `*why` naming the failing constraint.
  bool Check(std::string* why) const;
};

// The median of sample / model along one incidence-plane band, per channel (the model evaluated at each
// sample's own directions).
struct BandAgreement {
  double theta0_deg = 0.0;
  std::string model;
  size_t samples = 0;
  double ratio[3] = {0, 0, 0};  // NaN where the band holds no sample
  // "incidence plane 30 deg: median sample / reconstruction R G B 1.002 0.998 1.010 over 812 samples", or
  // that the band holds no samples (never "nan").
  std::string BriefReport() const;
};

// A held-out photo shown: the median |render - photo| / photo of the regression that never saw it, and
// of the reconstruction that did (NaN without a reconstruction).
struct HeldOutRender {
  uint32_t image = 0;
  double median_abs_difference = 0.0;
  double in_sample_median_abs_difference = NAN;
};

// What the stage wrote; reads as failure until the folder was committed.
struct ReportResult {
  bool success = false;         // the report folder was committed
  std::string index_html;       // OUT/index.html
  std::string explorer_html;    // OUT/explorer.html (empty without the explorer)
  std::string title;            // the report's title
  size_t samples = 0;           // samples in the run folder
  uint32_t photo = 0;           // the photo shown (chosen or given)
  double phase_deg = 0.0;       // its median phase angle
  bool photo_shown = false;     // the measured photo and the renders of it were written
  std::string photo_note;       // why not, when the samples' session could not be read
  bool reconstruction = false;  // a reconstruction was found (its path in reconstruction_path)
  std::string reconstruction_path;
  std::vector<std::string> fits;        // the fitted models found beside it ("lafortune", "ggx")
  bool truth = false;                   // the run's truth-comparison.json names a truth
  std::vector<BandAgreement> bands;     // incidence-plane agreement of the reconstruction with the samples
  std::vector<HeldOutRender> held_out;  // the held-out photos shown
  // One line: where, which photo, what was rendered.
  std::string BriefReport() const;
  // What `ibrdf report` prints: BriefReport(), a line per incidence-plane band, the explorer's path.
  std::vector<std::string> SummaryLines() const;
};

// The inputs of the report of `run_dir` (for the output guard): the run folder, every file in it but
// those of its default report folder RUN_DIR/report, and the reconstruction the options name.
std::vector<std::string> ReportInputs(const std::string& run_dir, const ReportOptions& options);

// Writes the report of `run_dir` (samples.npy; optionally its sidecar, summary.json, consistency.json,
// the reconstruction and truth-comparison.json) into `out_dir` (empty: RUN_DIR/report), atomically.
// Throws Error when run_dir is not a completed run folder, a reconstruction given in the options does
// not exist, the script or python is missing, or the script fails.
ReportResult WriteReport(const std::string& run_dir, const ReportOptions& options, const std::string& out_dir = "");

}  // namespace ibrdf
