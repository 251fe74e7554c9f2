// The scan stage end to end: read every input (each with its transform into the common
// frame), tessellate range grids by their neighbours and reconstruct unorganized points (CGAL),
// merge, clean, fit local-plane normals, and report convexity. `ibrdf scan` is a thin shell around it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/rigid3.h"
#include "core/session.h"
#include "scan/convexity.h"
#include "scan/local_plane_normals.h"
#include "scan/mesh_clean.h"
#include "scan/mesh_file.h"  // ScanSidecarPath
#include "scan/range_grid.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

struct ScanOptions {
  RangeGridOptions grid;       // range-grid tessellation
  CleanOptions clean;          // cleaning steps
  LocalPlaneOptions normals;   // local-plane normals
  ConvexityOptions convexity;  // convexity report
  // Unorganized points (no faces, no grid) are reconstructed with CGAL's advancing front; with false
  // they are an error.
  bool reconstruct_points = true;

  bool Check(std::string* why) const;
};

// The inputs of the stage are the session's type, ScanInputSpec (core/session.h): a file and its
// transform into the common frame (identity when absent). Here `file` is a path as the stage opens it
// (absolute, or relative to the working folder).

// Inputs listed in a Stanford .conf file: each of `files` must appear in it (by file name); an
// empty `files` takes every bmesh of the .conf that exists beside it. Throws Error otherwise.
std::vector<ScanInputSpec> InputsFromConf(const std::string& conf_path, const std::vector<std::string>& files);

// The raw scans of a session's mesh sample (/sample/scan_inputs), with absolute paths and their
// world_from_scan transforms. Throws Error naming the manifest unless the sample is a mesh with scans.
std::vector<ScanInputSpec> InputsFromSession(const Session& session);

// Where the stage's inputs come from (one of): a session's scan_inputs; a Stanford .conf, with or
// without `files`; plain `files`.
struct ScanSources {
  std::vector<std::string> files;  // scan files
  std::string conf;                // Stanford .conf file ("": none)
  std::string session;             // session folder or manifest ("": none)
};

// The inputs `sources` name (InputsFromSession, InputsFromConf or the files as given); `read` receives
// every file the stage reads (the scans, the .conf or the manifest), none of which may be an output.
// Throws Error for no inputs, or a session together with files or a .conf.
std::vector<ScanInputSpec> ResolveScanInputs(const ScanSources& sources, std::vector<std::string>* read);

struct ScanInputReport {
  std::string path;
  std::string kind;  // "range grid", "mesh" or "points"
  uint64_t points = 0, faces = 0;
  std::string detail;  // the tessellation's report for a range grid
};

struct ScanSummary {
  bool success = false;  // false until the whole stage ran
  std::vector<ScanInputReport> inputs;
  uint64_t reconstructed_faces = 0;  // by CGAL from unorganized points
  CleanReport clean;
  LocalPlaneResult normals;   // figures only: per-point vectors are cleared once stored in the mesh
  ConvexityReport convexity;  // likewise
  std::vector<std::pair<std::string, double>> step_seconds;
  double total_s = 0.0;
  // "scan: 2 inputs -> 80000 points, 150000 faces; normals RMS median 0.1 mm; convex 99.9 %"
  std::string BriefReport() const;
  // The one-screen summary printed by `ibrdf scan`.
  std::string Table() const;
  nlohmann::json ToJson() const;
};

struct ScanResult {
  ScanMesh mesh;
  ScanSummary summary;
};

// Runs the stage. Throws Error for unreadable inputs or an empty result.
ScanResult RunScan(const std::vector<ScanInputSpec>& inputs, const ScanOptions& options);

// Writes the mesh (ply_io.h WritePly) and its JSON sidecar <ply>.json (summary, options, units),
// both atomically.
void WriteScanOutputs(const std::string& ply_path, const ScanResult& result, const ScanOptions& options);

// ScanSidecarPath (the sidecar path, "<ply>.json") is in scan/mesh_file.h, included above.

}  // namespace ibrdf
