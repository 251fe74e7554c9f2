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
      "(PLY, PCD; COLMAP fused.ply), bring them into one frame (--conf, the Stanford .conf format, or a\n"
      "session's scan_inputs), tessellate, clean, fit a local plane at every point for its normal, and report\n"
      "convexity. Writes a PLY with normals and quality, and a JSON sidecar <out>.json (docs/scan.md).");
  struct Args {
    ScanSources sources;
    std::string out;
    ScanOptions options;
    bool no_outliers = false, overwrite = false;
  };
  auto args = std::make_shared<Args>();
  ScanOptions& o = args->options;
  auto option = [command](const char* name, auto& value, const char* help) {
    command->add_option(name, value, help)->capture_default_str();
  };
  command->add_option("inputs", args->sources.files, "Scan files (with --conf: each must be listed there; none: all)");
  command->add_option("--out", args->out, "Mesh to write (.ply); the sidecar goes to <out>.json")->required();
  command->add_option("--conf", args->sources.conf, "Stanford .conf file: per-scan transforms into one frame");
  command->add_option("--session", args->sources.session, "Session (folder or session.json): its scan_inputs");
  option("--max-edge-factor", o.grid.max_edge_factor, "Range grids: drop edges longer than this x the grid spacing");
  option("--max-edge-m", o.grid.max_edge_m, "Range grids: absolute edge limit in metres (0: use the factor)");
  command->add_flag("--no-outliers", args->no_outliers, "Skip the statistical outlier removal");
  option("--outlier-neighbours", o.clean.outlier_neighbours, "Outlier removal: neighbours per point");
  option("--outlier-stddev", o.clean.outlier_stddev, "Outlier removal: standard deviations above the mean distance");
  option("--min-piece-fraction", o.clean.min_piece_fraction, "Remove pieces with under this fraction of the faces");
  option("--radius-m", o.normals.radius_m, "Local-plane radius in metres (0: --radius-factor x the point spacing)");
  option("--radius-factor", o.normals.radius_spacing_factor, "Local-plane radius in median point spacings");
  option("--hull-tolerance-m", o.convexity.tolerance_m, "Convexity: distance counted as on the hull (0: auto)");
  option("--min-convex-fraction", o.convexity.min_convex_fraction, "Convexity: surface fraction on the hull");
  command->add_flag("--overwrite", args->overwrite, "Replace existing output files");
  command->callback([args] {
    args->options.clean.remove_outliers = !args->no_outliers;
    RequireValidOptions(args->options, "ibrdf scan");
    StageLog stage("scan");
    std::vector<std::string> read;
    const std::vector<ScanInputSpec> inputs = ResolveScanInputs(args->sources, &read);
    RequireWritableOutputs(args->out, {{ScanSidecarPath(args->out), "ibrdf scan 1"}}, args->overwrite, read);
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
