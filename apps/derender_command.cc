// ibrdf derender: a session's photos to a BRDF sample file (derender/derenderer.h) behind flags.
#include "apps/commands.h"
#include "core/session.h"
#include "derender/derenderer.h"

namespace ibrdf {

IBRDF_COMMAND(40, Derender) {
  auto* c = app.add_subcommand("derender",
                               "Turn every pixel of every photo into a BRDF sample: ray to the sample (an analytic "
                               "sphere or cylinder, or\nthe scanned mesh: Embree, normals from the scan's local-plane "
                               "fits), irradiance E = I cos(theta_i) / r^2,\nf = L / E per channel. Writes a .npy "
                               "sample file and a .json sidecar.");
  struct Args {
    std::string session, out;
    DerenderOptions options;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  DerenderOptions& o = args->options;
  c->add_option("session", args->session, "Session folder or session.json")->required();
  AddOutputFlags(*c, args->out, args->overwrite, "Sample file to write (.npy); the sidecar goes to <out>.json",
                 "Replace existing output files");
  AddOption(*c, "--max-theta-i-deg", o.max_theta_i_deg, "Grazing limit for incidence");
  AddOption(*c, "--max-theta-e-deg", o.max_theta_e_deg, "Grazing limit for exitance");
  AddOption(*c, "--min-signal", o.min_signal, "Signal floor (linear, normalized units)");
  AddOption(*c, "--stride", o.pixel_stride, "Use every n-th pixel in x and y");
  const auto visibility = [&o](const std::string& name) { VisibilityFromName(name, &o.visibility.emplace()); };
  c->add_option_function<std::string>("--visibility", visibility,
                                      "Mesh samples: shadow rays auto (as the scan's convexity report asks), on or off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  AddClearingFlag(*c, "--no-mixed-pixel-mask", o.mask_mixed_pixels,
                  "Mesh samples: keep pixels that straddle the silhouette (corner rays miss or jump in depth)");
  AddOption(*c, "--mixed-pixel-depth-factor", o.mixed_pixel_depth_factor,
            "Mesh samples: depth jump across a pixel, in pixel footprints, that marks it mixed");
  AddOption(*c, "--max-normal-fit-rms-m", o.max_normal_fit_rms_m,
            "Mesh samples: reject hits whose local-plane fit RMS exceeds this (metres; 0: no limit)");
  AddOption(*c, "--min-fit-neighbours", o.min_fit_neighbours,
            "Mesh samples: reject hits on faces with a corner fitted from fewer points");
  AddOption(*c, "--shadow-edge-deg", o.shadow_edge_deg, "Shadow rays on: reject lit pixels this near a shadow edge");
  AddOption(*c, "--shadow-edge-rays", o.shadow_edge_rays, "Shadow rays on: rays to the light's disc (0: no test)");
  c->callback([args] {
    RequireValidOptions(args->options, "ibrdf derender");
    StageLog stage("derender");
    const Session session = Session::Load(args->session);
    std::vector<std::string> inputs = SessionInputs(session);
    if (!session.sample.mesh_file.empty()) inputs.push_back(session.AbsolutePath(session.sample.mesh_file) + ".json");
    RequireWritableOutputs(args->out, {{SidecarPath(args->out), "ibrdf-samples"}}, args->overwrite, inputs);
    DerenderToFile(session, args->options, args->out);
    Log(1, "samples written to " + args->out);
  });
}

}  // namespace ibrdf
