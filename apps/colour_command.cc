// ibrdf colour: the colour chart's matrix from camera RGB to linear sRGB or XYZ (calibrate/colour_chart.h:
// the chart found by its corner patches or by OpenCV's mcc) behind flags.
#include <cstdio>

#include "apps/commands.h"
#include "calibrate/colour_chart.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/session.h"

namespace ibrdf {
namespace {

void AddColourCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "colour",
      "Fit a 3x3 matrix from the camera's RGB to linear sRGB (or XYZ) on the session's colour-chart photo\n"
      "(a ColorChecker Classic; colour_chart block): the 24 patches read through the session's radiometric\n"
      "chain, clipped and too dark ones left out, least squares against the chart's published reference\n"
      "values. The chart is located by the block's corner patches, else detected (OpenCV mcc). Writes\n"
      "OUT/session.json (the session with the matrix: `ibrdf derender` applies it to every sample),\n"
      "OUT/colour.json (matrix and per-patch residuals) and OUT/chart.png (the patches read).");
  struct Args {
    std::string session, out;
    ColourChartOptions options;
    bool detect = false, overwrite = false;
    AcceptedChecks accept;
  };
  auto args = std::make_shared<Args>();
  ColourChartOptions& o = args->options;
  command->add_option("session", args->session, "Session folder or session.json with a colour_chart block")->required();
  command->add_option("--out", args->out, "Folder for the session with the colour matrix")->required();
  command->add_option("--patch-fraction", o.patch_fraction, "Read-out square of each patch, in patch pitches")
      ->capture_default_str();
  command
      ->add_option("--min-patch-signal", o.min_patch_signal,
                   "Leave out patches whose brightest channel's mean signal is below this (normalized units)")
      ->capture_default_str();
  command
      ->add_option("--min-channel-fraction", o.min_channel_fraction,
                   "Leave out patches with a channel below this fraction of the brightest patch's (a black channel)")
      ->capture_default_str();
  command->add_option("--min-patches", o.min_patches, "Usable patches the fit needs")->capture_default_str();
  command->add_flag("--detect", args->detect, "Detect the chart (OpenCV mcc) even where the session gives its corners");
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->add_option("--accept", args->accept.names,
                      "Proceed although these checks fail (comma-separated, or all); recorded in colour.json")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  command->callback([args] {
    StageLog stage("colour");
    const Session session = Session::Load(args->session);
    if (!session.colour_chart) {
      ThrowError(session.manifest_path, "has no colour_chart block (docs/session-format.md): nothing to fit");
    }
    RequireWritableOutput(args->out, args->overwrite, SessionInputs(session));
    ColourChartFit fit = LocateAndFitColourChart(session, args->options, args->detect);
    Log(1, fit.BriefReport());
    for (const ColourPatch& patch : fit.patches) {
      char line[200];
      if (patch.excluded.empty()) {
        std::snprintf(line, sizeof(line),
                      "  %2d %-14s camera (%.4g, %.4g, %.4g) -> (%.4f, %.4f, %.4f), reference "
                      "(%.4f, %.4f, %.4f): %.2f %%",
                      patch.index + 1, patch.name.c_str(), patch.camera_rgb[0], patch.camera_rgb[1],
                      patch.camera_rgb[2], patch.corrected[0], patch.corrected[1], patch.corrected[2],
                      patch.reference[0], patch.reference[1], patch.reference[2], 100.0 * patch.residual);
        Log(1, line);
      } else {
        std::snprintf(line, sizeof(line), "  %2d %-14s left out: ", patch.index + 1, patch.name.c_str());
        Log(1, line + patch.excluded);
      }
    }
    // Nothing is written when the fit cannot be trusted, unless the user accepted it by name.
    fit.verdicts = ColourChartVerdicts(fit);
    EnforceVerdicts(&fit.verdicts, args->accept, session.manifest_path + ": /colour_chart");
    WriteColourStage(session, fit, args->out, args->overwrite);
    Log(1, "session with the colour matrix written to " + args->out + "/session.json (fit in " + args->out +
               "/colour.json)");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(35, AddColourCommand);

}  // namespace ibrdf
