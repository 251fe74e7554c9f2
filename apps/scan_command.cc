// ibrdf scan: range scans, meshes and point clouds into one clean sample mesh with local-plane normals.
#include <iostream>

#include "apps/commands.h"
#include "core/error.h"
#include "core/logging.h"
#include "scan/scan_pipeline.h"

namespace ibrdf {

namespace {
void AddScanCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "scan",
      "Read range scans (PLY range grids), meshes (PLY, OBJ, OFF, STL; COLMAP meshed-*.ply) and point clouds\n"
      "(PLY, PCD; COLMAP fused.ply), bring them into one frame (--conf, the Stanford .conf format), tessellate,\n"
      "clean, fit a local plane at every point for its normal, and report convexity. Writes a PLY with normals\n"
      "and quality, and a JSON sidecar <out>.json (docs/scan.md).");
  struct Args {
    std::vector<std::string> inputs;
    std::string out, conf;
    ScanOptions options;
    bool no_outliers = false;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("inputs", args->inputs,
                      "Scan files (with --conf: each must be listed there; none: all it lists)");
  command->add_option("--out", args->out, "Mesh to write (.ply); the sidecar goes to <out>.json")->required();
  command->add_option("--conf", args->conf, "Stanford .conf file: per-scan transforms into one frame");
  command
      ->add_option("--max-edge-factor", args->options.grid.max_edge_factor,
                   "Range grids: drop triangles with an edge longer than this times the grid spacing")
      ->capture_default_str();
  command
      ->add_option("--max-edge-m", args->options.grid.max_edge_m,
                   "Range grids: absolute edge limit in metres (0: use the factor)")
      ->capture_default_str();
  command->add_flag("--no-outliers", args->no_outliers, "Skip the statistical outlier removal");
  command
      ->add_option("--outlier-neighbours", args->options.clean.outlier_neighbours,
                   "Outlier removal: neighbours per point")
      ->capture_default_str();
  command
      ->add_option("--outlier-stddev", args->options.clean.outlier_stddev,
                   "Outlier removal: standard deviations above the mean distance")
      ->capture_default_str();
  command
      ->add_option("--min-piece-fraction", args->options.clean.min_piece_fraction,
                   "Remove connected pieces with fewer than this fraction of the faces")
      ->capture_default_str();
  command
      ->add_option("--radius-m", args->options.normals.radius_m,
                   "Local-plane radius in metres (0: --radius-factor times the point spacing)")
      ->capture_default_str();
  command
      ->add_option("--radius-factor", args->options.normals.radius_spacing_factor,
                   "Local-plane radius as a multiple of the median point spacing")
      ->capture_default_str();
  command
      ->add_option("--hull-tolerance-m", args->options.convexity.tolerance_m,
                   "Convexity: distance to the hull counted as on it (0: a fraction of the size)")
      ->capture_default_str();
  command
      ->add_option("--min-convex-fraction", args->options.convexity.min_convex_fraction,
                   "Convexity: surface fraction within the tolerance for a convex sample")
      ->capture_default_str();
  command->add_flag("--overwrite", args->overwrite, "Replace existing output files");
  command->callback([args] {
    StageLog stage("scan");
    args->options.clean.remove_outliers = !args->no_outliers;
    std::string why;
    if (!args->options.Check(&why)) ThrowError("ibrdf scan", "bad option: " + why);
    std::vector<ScanInput> inputs;
    if (!args->conf.empty()) {
      inputs = InputsFromConf(args->conf, args->inputs);
    } else {
      if (args->inputs.empty()) ThrowError("ibrdf scan", "no input files (give scan files, or --conf)");
      for (const std::string& path : args->inputs) inputs.push_back({path, std::nullopt});
    }
    std::vector<std::string> input_paths;
    for (const ScanInput& input : inputs) input_paths.push_back(input.path);
    if (!args->conf.empty()) input_paths.push_back(args->conf);
    RequireWritableOutput(args->out, args->overwrite, input_paths);
    RequireWritableOutput(ScanSidecarPath(args->out), args->overwrite, input_paths);
    const ScanResult result = RunScan(inputs, args->options);
    WriteScanOutputs(args->out, result, args->options);
    if (Verbosity() >= 1) std::cout << result.summary.Table();
    Log(1, result.summary.BriefReport());
    Log(1, "mesh written to " + args->out + ", summary to " + ScanSidecarPath(args->out));
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(20, AddScanCommand);

}  // namespace ibrdf
