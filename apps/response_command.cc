// ibrdf response: the camera's response curve from the session's exposure brackets
// (calibrate/response_calibration.h: OpenCV's Debevec calibration, Robertson's as a cross-check)
// behind flags.
#include "apps/commands.h"
#include "calibrate/response_calibration.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/session.h"

namespace ibrdf {
namespace {

void AddResponseCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "response",
      "Measure the camera's response curve (file value -> linear signal) from the session's exposure\n"
      "brackets: photos of one pose under one light at several exposures (exposure_s x gain), the scene\n"
      "static between them. Each bracket is calibrated on its own (Debevec and Malik, OpenCV's photo\n"
      "module) from pixels spread over its values; the curves are combined level by level and their\n"
      "spread is the curve's uncertainty; Robertson's calibration cross-checks it. Verdicts judge the\n"
      "brackets (docs/verdicts.md); a failed one stops with its remedy unless accepted. Writes\n"
      "OUT/session.json (radiometry.response as a 256-level table with its uncertainty, black level 0:\n"
      "the curve includes it) and OUT/response.json (the curve, the figures, the brackets, the verdicts).");
  struct Args {
    std::string session, out;
    ResponseCalibrationOptions options;
    bool overwrite = false;
    AcceptedChecks accept;
  };
  auto args = std::make_shared<Args>();
  ResponseCalibrationOptions& o = args->options;
  command->add_option("session", args->session, "Session folder or session.json with exposure brackets")->required();
  command->add_option("--out", args->out, "Folder for the session with the measured response")->required();
  command->add_option("--pixels", o.pixels_per_bracket, "Pixels chosen per bracket (16 to 4096)")->capture_default_str();
  command->add_option("--smoothness", o.smoothness, "Debevec's smoothness weight (lambda)")->capture_default_str();
  command->add_option("--max-brackets", o.max_brackets, "Brackets calibrated at most (chosen evenly)")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->add_option("--accept", args->accept.names,
                      "Proceed although these checks fail (comma-separated, or all); recorded in response.json")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  command->callback([args] {
    StageLog stage("response");
    const Session session = Session::Load(args->session);
    RequireWritableOutput(args->out, args->overwrite, SessionInputs(session));
    ResponseCalibration calibration = CalibrateResponse(session, args->options);
    Log(1, calibration.BriefReport());
    for (const ResponseBracket& bracket : calibration.brackets) {
      if (!bracket.left_out.empty()) Log(1, "  bracket of " + bracket.first_photo + " left out: " + bracket.left_out);
    }
    // Nothing is written when the curve cannot be trusted, unless the user accepted it by name.
    EnforceVerdicts(&calibration.verdicts, args->accept, session.manifest_path + ": /radiometry/response");
    WriteResponseStage(session, calibration, args->out, args->overwrite);
    Log(1, "session with the measured response written to " + args->out + "/session.json (curve in " + args->out +
               "/response.json)");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(22, AddResponseCommand);

}  // namespace ibrdf
