// ibrdf uniformity: whether a sample file's object is one material (spatial/uniformity.h) behind flags.
#include <filesystem>
#include <optional>

#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "core/png_writer.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "spatial/surface_points.h"
#include "spatial/uniformity.h"

namespace ibrdf {

IBRDF_COMMAND(55, Uniformity) {
  auto* c = app.add_subcommand(
      "uniformity",
      "Check that the sample is one material: the surface is divided into cells (each sample's pixel traced\n"
      "again onto the session's sample), and each cell's samples are compared with the reconstructed BRDF\n"
      "(the median ratio per channel). A cell deviates when its ratio is off the object's by more than\n"
      "--deviation and by more than its noise; the verdict uniformity.cells fails when too many do\n"
      "(docs/spatial.md). Writes OUT/uniformity.json (figures, verdicts, the cells) and OUT/map.png (the photo\n"
      "with most samples, each sample pixel coloured by its cell: red above the object's BRDF, blue below).\n"
      "A failed check writes both, then exits non-zero unless accepted.");
  struct Args {
    std::string samples, brdf, session, out;
    bool overwrite = false;
    double cell_mm = 0.0;
    UniformityOptions options;
    AcceptedChecks accept;
  };
  auto args = std::make_shared<Args>();
  c->add_option("samples", args->samples, "Sample file (.npy) of `ibrdf derender`")->required();
  c->add_option("--brdf", args->brdf, "The BRDF reconstructed from the samples (a MERL table, reconstruction/brdf.binary)")
      ->required();
  c->add_option("--session", args->session,
                "The session the samples were derendered from (default: the one their sidecar names)");
  AddOutputFlags(*c, args->out, args->overwrite, "Folder for uniformity.json and map.png",
                 "Replace an existing output folder");
  AddOption(*c, "--cell-mm", args->cell_mm, "Edge of the surface cells, mm (0: the sample's bounding radius / 16)");
  AddOption(*c, "--min-cell-samples", args->options.min_cell_samples, "Samples a cell needs to be scored");
  AddOption(*c, "--deviation", args->options.deviation,
            "A cell deviates beyond this relative difference (0.25: 1.25x or 1 / 1.25x)");
  AddOption(*c, "--noise-sigmas", args->options.noise_sigmas, "... and beyond this many standard errors of its own");
  AddOption(*c, "--cluster-min-theta-h-deg", args->options.cluster_min_theta_h_deg,
            "The cells are grouped by their samples with theta_h at least this (0: all)");
  c->add_option("--accept", args->accept.names,
                "Proceed although these checks fail (comma-separated, or all); recorded in uniformity.json")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  c->callback([args] {
    StageLog stage("uniformity");
    args->options.cell_m = args->cell_mm * 1e-3;
    std::string why;
    if (!args->options.Check(&why)) ThrowError("uniformity", why);
    const Session session = Session::Load(SessionOfSamples(args->samples, args->session));
    RequireWritableOutput(args->out, args->overwrite, {args->samples, SidecarPath(args->samples), args->brdf,
                                                        session.manifest_path});
    const MerlBrdf reference(args->brdf);
    UniformityResult result = MeasureUniformity(session, args->samples, reference, args->options);
    Log(1, result.BriefReport());
    // The evidence is written whatever the verdict: a failed check points at its map.
    std::optional<Error> failure;
    try {
      EnforceVerdicts(&result.verdicts, args->accept, args->samples + ": uniformity");
    } catch (const Error& error) {
      failure = error;
    }
    const Image map = UniformityMap(session, args->samples, result, args->options);
    AtomicDirectory directory(args->out, args->overwrite);
    const std::filesystem::path folder = directory.temporary_path();
    nlohmann::json json = result.ToJson(true);
    json["samples_file"] = std::filesystem::absolute(args->samples).lexically_normal().string();
    json["brdf"] = std::filesystem::absolute(args->brdf).lexically_normal().string();
    json["session"] = session.manifest_path;
    json["map"] = "map.png";
    WriteJsonFile((folder / "uniformity.json").string(), json);
    WritePlainPng((folder / "map.png").string(), map, PixelFormat::kUint8, PngEncoding::kAsOpenImageIo);
    directory.Commit();
    Log(1, "uniformity written to " + args->out + " (map: " + args->out + "/map.png)");
    if (failure) throw *failure;
  });
}

}  // namespace ibrdf
