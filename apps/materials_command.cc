// ibrdf materials: the uniformity check's groups of cells, each reconstructed as a material of its own
// (spatial/material_groups.h) behind flags.
#include <filesystem>
#include <memory>
#include <optional>

#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "core/truth_file.h"
#include "core/verdict.h"
#include "spatial/material_groups.h"
#include "spatial/surface_points.h"
#include "synth/material_map.h"

namespace ibrdf {

IBRDF_COMMAND(57, Materials) {
  auto* c = app.add_subcommand(
      "materials",
      "Measure each group of the uniformity check's cells as a material of its own: every sample is traced\n"
      "again onto the session's sample and takes its cell's group (uniformity.json), and each group's samples\n"
      "are reconstructed as `ibrdf reconstruct` does (OUT/group-K: table, fits, exports). One group is the\n"
      "object's own reconstruction and is not repeated. With --truth (a synthetic session's truth.json) the\n"
      "groups are scored: each sample's true material against its group, and each group's reconstruction\n"
      "against the material most of its samples carry. Writes OUT/materials.json (docs/spatial.md).");
  struct Args {
    std::string samples, uniformity, session, truth, out;
    bool overwrite = false;
    double margin_mm = 2.0;
    MaterialGroupsOptions options;
    AcceptedChecks accept;
  };
  auto args = std::make_shared<Args>();
  ReconstructOptions& r = args->options.reconstruct;
  c->add_option("samples", args->samples, "Sample file (.npy) of `ibrdf derender`")->required();
  c->add_option("--uniformity", args->uniformity, "uniformity.json of `ibrdf uniformity` on these samples")->required();
  c->add_option("--session", args->session,
                "The session the samples were derendered from (default: the one their sidecar names)");
  c->add_option("--truth", args->truth,
                "truth.json of a synthetic session (a material map or one material) to score the groups against");
  AddOutputFlags(*c, args->out, args->overwrite, "Folder for materials.json and the groups' reconstructions",
                 "Replace an existing output folder");
  AddOption(*c, "--margin-mm", args->margin_mm, "Labels are scored this far from the truth's boundaries and blends");
  AddOption(*c, "--min-group-samples", args->options.min_group_samples, "A smaller group is not reconstructed");
  AddOption(*c, "--neighbours", args->options.neighbours,
            "Each sample takes the group of its nearest off-peak samples (this many, within a cell)");
  AddOption(*c, "--purity", args->options.purity,
            "An off-peak value beyond this of every group's centre (0.25: 1.25x) is a mix");
  c->add_option("--accept", args->accept.names,
                "Proceed although these checks fail (materials.measured, materials.cells, or all); recorded in "
                "materials.json")
      ->delimiter(',')
      ->type_name("CHECK[,CHECK...]");
  AddOption(*c, "--photo", args->options.photo,
            "The photo predicted from the model and written as a pbrt-v4 scene (-1: the one with the most samples)");
  c->add_flag("--hold-out", args->options.hold_out,
              "Leave --photo's samples out of the groups, reconstructions and weights: a held-out prediction");
  AddClearingFlag(*c, "--no-fits", r.fits, "Skip each group's Lafortune and GGX fits");
  AddClearingFlag(*c, "--no-bsdf", r.bsdf, "Skip each group's NAME.bsdf");
  c->add_option("--name", r.name, "Name of the groups' materials (NAME-group-K; default: material-group-K)");
  c->callback([args] {
    StageLog stage("materials");
    args->options.boundary_margin_m = args->margin_mm * 1e-3;
    std::string why;
    if (!args->options.Check(&why)) ThrowError("materials", why);
    const Session session = Session::Load(SessionOfSamples(args->samples, args->session));
    RequireWritableOutput(
        args->out, args->overwrite,
        {args->samples, SidecarPath(args->samples), args->uniformity, args->truth, session.manifest_path});
    const nlohmann::json uniformity = ReadJsonFile(args->uniformity);
    std::optional<MaterialMap> map;
    std::string truth_file;
    if (!args->truth.empty()) {
      if (IsSpatiallyVaryingTruth(args->truth)) {
        map.emplace(MaterialMap::FromJson(ReadJsonFile(args->truth)["material_map"], args->truth));
      } else {
        truth_file = std::filesystem::absolute(args->truth).lexically_normal().string();
      }
    }
    AtomicDirectory directory(args->out, args->overwrite);
    const std::string folder = directory.temporary_path();
    MaterialGroupsResult result = MeasureMaterialGroups(session, args->samples, uniformity, args->uniformity,
                                                        map ? &*map : nullptr, truth_file, args->options, folder);
    // The evidence is written whatever the verdict: a failed check points at its cells.
    std::optional<Error> failure;
    try {
      EnforceVerdicts(&result.verdicts, args->accept, args->samples + ": materials");
    } catch (const Error& error) {
      failure = error;
    }
    nlohmann::json json = result.ToJson();
    json["samples_file"] = std::filesystem::absolute(args->samples).lexically_normal().string();
    json["uniformity"] = std::filesystem::absolute(args->uniformity).lexically_normal().string();
    json["session"] = session.manifest_path;
    if (!args->truth.empty()) json["truth_file"] = std::filesystem::absolute(args->truth).lexically_normal().string();
    WriteJsonFile(folder + "/materials.json", json);
    directory.Commit();
    Log(1, result.BriefReport());
    Log(1, "materials written to " + args->out);
    if (failure) throw *failure;
  });
}

}  // namespace ibrdf
