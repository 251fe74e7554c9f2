// The scanned mesh as a file, for the stages that read it (derender): a triangle mesh's readers and
// the path of the scan stage's sidecar. Kept apart from scan_io.h and scan_pipeline.h, whose point-cloud
// readers and pipeline link PCL (and through it VTK): a binary that only reads meshes starts without
// them (docs/decisions.md, "Speed").
#pragma once

#include <string>

#include "scan/scan_mesh.h"

namespace ibrdf {

// Reads a triangle mesh: PLY (ply_io.h, with the scan stage's per-point normals and fit quality), or
// OBJ, OFF or STL (OpenMesh). Throws Error naming the file for a point cloud (.pcd: no faces, run
// `ibrdf scan` on it) or another extension.
ScanMesh ReadTriangleMeshFile(const std::string& path);

// The scan stage's sidecar of a mesh: "<ply>.json".
std::string ScanSidecarPath(const std::string& ply_path);

}  // namespace ibrdf
