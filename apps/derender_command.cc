// ibrdf derender: a session's photos to a BRDF sample file (derender/derenderer.h) behind flags.
#include "apps/commands.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/derenderer.h"

namespace ibrdf {
namespace {

void AddDerenderCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "derender",
      "Turn every pixel of every photo into a BRDF sample: ray to the sample (an analytic sphere or\n"
      "cylinder, or the scanned mesh: Embree, normals from the scan's local-plane fits), irradiance\n"
      "E = I cos(theta_i) / r^2, f = L / E per channel. Writes a .npy sample file and a .json sidecar.");
  struct Args {
    std::string session, out;
    DerenderOptions options;
    bool overwrite = false;
    std::string visibility;
  };
  auto args = std::make_shared<Args>();
  DerenderOptions& o = args->options;
  command->add_option("session", args->session, "Session folder or session.json")->required();
  command->add_option("--out", args->out, "Sample file to write (.npy); the sidecar goes to <out>.json")->required();
  command->add_option("--max-theta-i-deg", o.max_theta_i_deg, "Grazing limit for incidence")->capture_default_str();
  command->add_option("--max-theta-e-deg", o.max_theta_e_deg, "Grazing limit for exitance")->capture_default_str();
  command->add_option("--min-signal", o.min_signal, "Signal floor (linear, normalized units)")->capture_default_str();
  command->add_option("--stride", o.pixel_stride, "Use every n-th pixel in x and y")->capture_default_str();
  command
      ->add_option("--visibility", args->visibility,
                   "Mesh samples: shadow rays auto (where the scan's convexity report asks for them), on or "
                   "off; overrides the session's sample.visibility")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->each([args](const std::string& name) { VisibilityFromName(name, &args->options.visibility.emplace()); });
  // A plain flag inverted in its callback: CLI11 shows a negated flag ("!--no-x") as "--no-x{false}".
  command->add_flag_callback(
      "--no-mixed-pixel-mask", [args] { args->options.mask_mixed_pixels = false; },
      "Mesh samples: keep pixels that straddle the silhouette (corner rays miss or jump in depth)");
  command
      ->add_option("--mixed-pixel-depth-factor", o.mixed_pixel_depth_factor,
                   "Mesh samples: depth jump across a pixel, in pixel footprints, that marks it mixed")
      ->capture_default_str();
  command
      ->add_option("--max-normal-fit-rms-m", o.max_normal_fit_rms_m,
                   "Mesh samples: reject hits whose local-plane fit RMS exceeds this (metres; 0: no limit)")
      ->capture_default_str();
  command
      ->add_option("--min-fit-neighbours", o.min_fit_neighbours,
                   "Mesh samples: reject hits on faces with a corner fitted from fewer points")
      ->capture_default_str();
  command
      ->add_option("--shadow-edge-deg", o.shadow_edge_deg,
                   "Mesh samples, shadow rays on: reject lit pixels within this angle of a shadow edge")
      ->capture_default_str();
  command
      ->add_option("--shadow-edge-rays", o.shadow_edge_rays,
                   "Mesh samples, shadow rays on: rays to the disc around the light (0: no shadow-edge test)")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace existing output files");
  command->callback([args] {
    RequireValidOptions(args->options, "ibrdf derender");
    StageLog stage("derender");
    const Session session = Session::Load(args->session);
    std::vector<std::string> inputs = session.InputFiles();
    inputs.push_back(session.manifest_path);
    inputs.push_back(session.directory);
    if (!session.sample.mesh_file.empty()) inputs.push_back(session.AbsolutePath(session.sample.mesh_file) + ".json");
    RequireWritableOutputs(args->out, {{SidecarPath(args->out), "ibrdf-samples"}}, args->overwrite, inputs);
    DerenderToFile(session, args->options, args->out);
    Log(1, "samples written to " + args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(40, AddDerenderCommand);

}  // namespace ibrdf
