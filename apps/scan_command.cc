// ibrdf scan: range scans, meshes and point clouds into one clean sample mesh with local-plane normals.
#include <iostream>

#include "apps/commands.h"
#include "scan/scan_pipeline.h"

namespace ibrdf {

IBRDF_COMMAND(20, Scan) {
  auto* c = app.add_subcommand(
      "scan",
      "Range scans (PLY grids), meshes (PLY, OBJ, OFF, STL) and point clouds (PLY, PCD; COLMAP's too) into one frame\n"
      "(--conf, the Stanford .conf format, or a session's scan_inputs), tessellated and cleaned, with local-plane\n"
      "normals and a convexity report: a PLY with normals and quality, and a JSON sidecar <out>.json (docs/scan.md).");
  struct Args {
    ScanSources sources;
    std::string out;
    ScanOptions o;
    bool overwrite = false;
  };
  auto args = std::make_shared<Args>();
  ScanOptions& o = args->o;
  c->add_option("inputs", args->sources.files, "Scan files (with --conf: each must be listed there; none: all)");
  AddOutputFlags(*c, args->out, args->overwrite, "Mesh to write (.ply); the sidecar goes to <out>.json",
                 "Replace existing output files");
  c->add_option("--conf", args->sources.conf, "Stanford .conf file: per-scan transforms into one frame");
  c->add_option("--session", args->sources.session, "Session (folder or session.json): its scan_inputs");
  AddOption(*c, "--max-edge-factor", o.grid.max_edge_factor, "Range grids: drop edges over this x the grid spacing");
  AddOption(*c, "--max-edge-m", o.grid.max_edge_m, "Range grids: absolute edge limit in metres (0: use the factor)");
  AddClearingFlag(*c, "--no-outliers", o.clean.remove_outliers, "Skip the statistical outlier removal");
  AddOption(*c, "--outlier-neighbours", o.clean.outlier_neighbours, "Outlier removal: neighbours per point");
  AddOption(*c, "--outlier-stddev", o.clean.outlier_stddev, "Outlier removal: standard deviations above the mean");
  AddOption(*c, "--min-piece-fraction", o.clean.min_piece_fraction, "Remove pieces with under this fraction of faces");
  AddOption(*c, "--radius-m", o.normals.radius_m, "Local-plane radius, metres (0: --radius-factor x point spacing)");
  AddOption(*c, "--radius-factor", o.normals.radius_spacing_factor, "Local-plane radius in median point spacings");
  AddOption(*c, "--hull-tolerance-m", o.convexity.tolerance_m, "Convexity: distance counted as on the hull (0: auto)");
  AddOption(*c, "--min-convex-fraction", o.convexity.min_convex_fraction, "Convexity: surface fraction on the hull");
  c->callback([args] {
    RequireValidOptions(args->o, "ibrdf scan");
    StageLog stage("scan");
    std::vector<std::string> read;
    const std::vector<ScanInputSpec> inputs = ResolveScanInputs(args->sources, &read);
    RequireWritableOutputs(args->out, {{ScanSidecarPath(args->out), "ibrdf scan 1"}}, args->overwrite, read);
    const ScanResult result = RunScan(inputs, args->o);
    WriteScanOutputs(args->out, result, args->o);
    if (Verbosity() >= 1) std::cout << result.summary.Table();
    Log(1, result.summary.BriefReport());
    Log(1, "mesh written to " + args->out + ", summary to " + ScanSidecarPath(args->out));
  });
}

}  // namespace ibrdf
