// ibrdf run: the whole workflow (synth for a recipe, scan, align, derender, check, compare, reconstruct,
// report) into one run folder, each stage a child process of this same binary, skipped when its stamp
// says it is up to date (workflow/run_folder.h, workflow/measurement.h). Decisions: docs/workflow.md.
#include <sstream>

#include <tbb/global_control.h>

#include "apps/commands.h"
#include "core/version.h"
#include "workflow/run_folder.h"

namespace ibrdf {

IBRDF_COMMAND(80, Run) {
  auto* c = app.add_subcommand(
      "run",
      "The whole workflow into one folder: (synth, for a recipe) -> scan -> align -> derender -> check -> compare ->\n"
      "reconstruct -> uniformity -> report, each stage a child `ibrdf` process, skipped when its outputs are newer than its inputs\n"
      "and its options unchanged (DIR/stamps/): interrupted, it resumes. Writes DIR/summary.json (docs/workflow.md).");
  struct Args {
    std::string input, out;
    MeasurementOptions o;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  MeasurementOptions& o = args->o;
  c->add_option("session", args->input, "Session folder or session.json; or a recipe folder (samples/<name>)")
      ->required();
  AddOutputFlags(*c, args->out, args->overwrite,
                 "Run folder (created; one of the same input is resumed, of another refused unless --overwrite)",
                 "Empty a run folder that holds another input's run before running (nothing else is touched)");
  AddOption(*c, "--stride", o.pixel_stride, "derender: every n-th pixel in x and y");
  c->add_option("--degree", o.degree, "reconstruct: local polynomial degree (default: reconstruct's)");
  c->add_option("--radius-h-deg", o.radius_h_deg, "reconstruct: kernel radius along the sheets (default: its own)");
  c->add_option("--radius-d-deg", o.radius_d_deg, "reconstruct: kernel radius across the sheets (default: its own)");
  AddClearingFlag(*c, "--no-fits", o.fits, "reconstruct: skip the Lafortune and GGX fits");
  c->add_flag("--check-regression", o.check_regression, "check: also the regression checks (held-out photos)");
  AddClearingFlag(*c, "--no-report", o.report, "Skip the HTML report");
  c->add_flag("--spatial", o.spatial,
              "materials: measure each group of the uniformity check's cells as a material of its own (accepts\n"
              "uniformity.cells, recorded; docs/spatial.md)");
  c->add_flag("--force", o.force, "Re-run every stage, up to date or not");
  AddClearingFlag(*c, "--sequential", o.concurrent_sample_stages,
                  "Run check and compare after reconstruct, not beside it (the outputs are the same)");
  // Arguments passed to a stage: in the order of these options (CLI11 runs their callbacks so), the
  // --STAGE-args words before the named options.
  using StageArgs = std::vector<std::string> MeasurementOptions::*;
  const StageArgs scan = &MeasurementOptions::scan_args, response = &MeasurementOptions::response_args,
                  align = &MeasurementOptions::align_args, lights = &MeasurementOptions::lights_args,
                  colour = &MeasurementOptions::colour_args, derender = &MeasurementOptions::derender_args,
                  check = &MeasurementOptions::check_args, reconstruct = &MeasurementOptions::reconstruct_args,
                  uniformity = &MeasurementOptions::uniformity_args, materials = &MeasurementOptions::materials_args,
                  report = &MeasurementOptions::report_args;
  const struct {
    const char* flag;
    StageArgs target;
    const char *stage, *help;
  } more[] = {{"--scan-args", scan, "scan", "--no-outliers --radius-factor 3"},
              {"--response-args", response, "response", "--pixels 800 --smoothness 30"},
              {"--align-args", align, "align", "--max-rms-px 2 --no-cylinder"},
              {"--lights-args", lights, "lights white", "--min-signal 0.02"},
              {"--colour-args", colour, "colour", "--min-patches 12 --detect"},
              {"--derender-args", derender, "derender", "--shadow-edge-deg 2"},
              {"--check-args", check, "check", "--theta-bin-deg 5 --phi-bin-deg 10"},
              {"--reconstruct-args", reconstruct, "reconstruct", "--degree 1 --no-fold"},
              {"--uniformity-args", uniformity, "uniformity", "--cell-mm 4 --accept uniformity.cells"},
              {"--materials-args", materials, "materials", "--margin-mm 3 --min-group-samples 5000"},
              {"--report-args", report, "report", "--angles-deg 20,40,60"}},
    named[] = {{"--calibrate", align, "align", "Calibrate the camera first from the ChArUco photos in this folder"},
               {"--colmap", align, "align", "A COLMAP sparse model whose poses replace the targets'"},
               {"--min-markers", align, "align", "Reference markers a photo needs"},
               {"--lobes", reconstruct, "reconstruct", "Lafortune lobes (1 to 3)"},
               {"--bandwidth", reconstruct, "reconstruct", "Kernel radii: given, loo or gcv"},
               {"--max-theta-deg", reconstruct, "reconstruct", "Tabulate up to this theta"},
               {"--visibility", derender, "derender", "Mesh samples' shadow rays: auto, on or off"},
               {"--max-theta-i-deg", derender, "derender", "Reject samples beyond this incidence angle"},
               {"--max-theta-e-deg", derender, "derender", "Reject samples beyond this exitance angle"},
               {"--min-signal", derender, "derender", "Reject pixels below this linear signal"},
               {"--held-out", report, "report", "Photos shown held out (a fit without each)"}};
  for (const auto& m : more) {
    std::vector<std::string>& target = o.*m.target;
    const auto add = [&target](const std::string& text) {
      std::istringstream words(text);
      for (std::string word; words >> word;) target.push_back(word);
    };
    c->add_option_function<std::string>(
         m.flag, add,
         std::string("More arguments for `ibrdf ") + m.stage + "`, one string split at spaces, e.g. \"" + m.help + "\"")
        ->type_name("\"ARGS\"");
  }
  for (const auto& n : named) {
    const std::string flag = n.flag;
    std::vector<std::string>& target = o.*n.target;
    const auto add = [&target, flag](const std::string& value) { target.insert(target.end(), {flag, value}); };
    c->add_option_function<std::string>(
         flag, add, std::string(n.stage) + ": " + n.help + " (passed to `ibrdf " + n.stage + " " + flag + "`)")
        ->type_name("VALUE");
  }
  // Each check goes to the stage that makes it: uniformity's own, the rest align's; "all" to both.
  c->add_option_function<std::string>(
       "--accept",
       [args](const std::string& value) {
         std::string to_align, to_uniformity;
         std::istringstream names(value);
         for (std::string name; std::getline(names, name, ',');) {
           const bool all = name == "all", its_own = name.rfind("uniformity.", 0) == 0;
           if (all || !its_own) to_align += (to_align.empty() ? "" : ",") + name;
           if (all || its_own) to_uniformity += (to_uniformity.empty() ? "" : ",") + name;
         }
         std::vector<std::string>&align_args = args->o.align_args, &uniformity_args = args->o.uniformity_args;
         if (!to_align.empty()) align_args.insert(align_args.end(), {"--accept", to_align});
         if (!to_uniformity.empty()) uniformity_args.insert(uniformity_args.end(), {"--accept", to_uniformity});
       },
       "align, uniformity: proceed although these checks fail (docs/verdicts.md; uniformity.* to `ibrdf uniformity\n"
       "--accept`, the others to `ibrdf align --accept`)")
      ->type_name("CHECK,...");
  c->add_option("--stop-after", o.stop_after,
                "Stop after this stage (synth, scan, response, align, lights, colour, derender, check,\n"
                "compare, reconstruct, uniformity, materials, report); later stages are left as they are");
  c->callback([args] {
    Timer wall;
    RequireValidOptions(args->o, "ibrdf run");
    const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    const nlohmann::json summary = RunInFolder(args->input, args->out, args->o, args->overwrite,
                                               ChildStageLauncher(threads), kIbrdfVersionLine, wall);
    for (const std::string& line : RunFolderReport(summary, args->out, wall.ElapsedSeconds())) Log(1, line);
  });
}

}  // namespace ibrdf
