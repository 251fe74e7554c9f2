// ibrdf derender: a session's photos to a BRDF sample file.
#include "apps/commands.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/derenderer.h"

namespace ibrdf {

namespace {
void AddDerenderCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "derender",
      "Turn every pixel of every photo into a BRDF sample: ray to the sample, normal, irradiance\n"
      "E = I cos(theta_i) / r^2, f = L / E per channel. Writes a .npy sample file and a .json sidecar.");
  struct Args {
    std::string session, out;
    DerenderOptions options;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("session", args->session, "Session folder or session.json")->required();
  command->add_option("--out", args->out, "Sample file to write (.npy); the sidecar goes to <out>.json")->required();
  command->add_option("--max-theta-i-deg", args->options.max_theta_i_deg, "Grazing limit for incidence")->capture_default_str();
  command->add_option("--max-theta-e-deg", args->options.max_theta_e_deg, "Grazing limit for exitance")->capture_default_str();
  command->add_option("--min-signal", args->options.min_signal, "Signal floor (linear, normalized units)")->capture_default_str();
  command->add_option("--stride", args->options.pixel_stride, "Use every n-th pixel in x and y")->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace existing output files");
  command->callback([args] {
    StageLog stage("derender");
    const Session session = Session::Load(args->session);
    std::vector<std::string> inputs = {session.manifest_path};
    for (size_t i = 0; i < session.photos.size(); ++i) inputs.push_back(session.PhotoPath(i));
    RequireWritableOutput(args->out, args->overwrite, inputs);
    RequireWritableOutput(SidecarPath(args->out), args->overwrite, inputs);
    Log(1, "session " + session.name + ": " + std::to_string(session.photos.size()) + " photos, " +
               SampleKindName(session.sample.kind) + " sample, response " +
               session.radiometry.response.Describe());
    const DerenderResult result = DerenderAnalytic(session, args->options);
    WriteSamples(args->out, result.samples);
    WriteJsonFile(SidecarPath(args->out), DerenderSidecar(session, args->options, result.summary));
    Log(1, result.summary.BriefReport());
    Log(1, "samples written to " + args->out);
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(40, AddDerenderCommand);

}  // namespace ibrdf
