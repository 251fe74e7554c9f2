// ibrdf report: the consistency report of a run folder (report/report_stage.h) behind flags.
#include <filesystem>

#include "apps/commands.h"
#include "report/report_stage.h"

namespace ibrdf {

IBRDF_COMMAND(70, Report) {
  auto* c = app.add_subcommand(
      "report",
      "The consistency report of an `ibrdf run` folder: OUT/index.html (self-contained) with the measured photo\n"
      "beside the renders of every model, spheres, coverage, incidence-plane plots, reciprocity and bilateral\n"
      "symmetry with the worst bins, timings; OUT/explorer.html, an offline BRDF explorer.\n"
      "Plots by matplotlib (scripts/report.py, Debian's python3).");
  struct Args {
    std::string run_dir, out;
    ReportOptions o;
  };
  auto args = std::make_shared<Args>();
  ReportOptions& o = args->o;
  c->add_option("run_dir", args->run_dir, "Run folder of `ibrdf run` (samples.npy, consistency.json, ...)")->required();
  c->add_option("--out", args->out, "Report folder to write (default: RUN_DIR/report)");
  c->add_option("--reconstruction", o.reconstruction,
                "Reconstruction folder of `ibrdf reconstruct` (or its brdf.binary) to show, wherever it is\n"
                "(default: RUN_DIR/reconstruction); the fits beside it are shown too");
  c->add_option("--photo", o.photo, "Photo index shown beside the renders (default: median phase angle)");
  auto* angles = AddOption(*c, "--angles-deg", o.angles_deg, "Incidence-plane angles theta_0, 1 to 8 in [0, 85]");
  AddDeprecatedAlias(*c, angles->delimiter(',')->expected(1, 8), "--angles", o.angles_deg);
  AddOption(*c, "--held-out", o.held_out_photos,
            "Photos shown held out (0 to 16): each beside the sample rendered by the regression fitted\n"
            "without it (the photos `ibrdf check --regression --held-out N` holds out; one fit each)");
  c->add_option("--title", o.title, "Report title (default: the recipe's or session's name)");
  AddRenamedOption(*c, "--render-size-px", "--render-size", o.render_size_px, "Rendered sphere size, pixels");
  AddClearingFlag(*c, "--no-explorer", o.explorer, "Skip explorer.html");
  c->add_flag("--overwrite", o.overwrite, "Replace an existing report folder");
  c->callback([args] {
    RequireValidOptions(args->o, "ibrdf report");
    StageLog stage("report");
    const std::string out = args->out.empty() ? (std::filesystem::path(args->run_dir) / "report").string() : args->out;
    RequireWritableOutput(out, args->o.overwrite, ReportInputs(args->run_dir, args->o));
    for (const std::string& line : WriteReport(args->run_dir, args->o, args->out).SummaryLines()) Log(1, line);
  });
}

}  // namespace ibrdf
