// Reading scans: one file of any supported format, and several scans with per-scan transforms (the
// Stanford `.conf` format) brought into one frame.
#pragma once

#include <string>
#include <vector>

#include "core/rigid3.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

// Reads a scan by its extension (case-insensitive): .ply (ply_io.h: meshes, point clouds such as
// COLMAP's fused.ply, Cyberware range grids), .obj/.off/.stl (OpenMesh), .pcd (PCL). Throws Error
// naming the file for an unknown extension, an empty or malformed file, or NaN coordinates.
ScanMesh ReadScanFile(const std::string& path);

// One `bmesh NAME tx ty tz qx qy qz qw` line of a Stanford .conf file: the rigid transform that
// brings scan NAME into the common frame, p_in_world = R(q)^-1 p_in_scan + t (the quaternion, as
// Stanford's scanalyze writes it, is the rotation from the common frame into the scan's; checked on
// the bunny, whose overlapping scans agree to 0.09 mm this way and miss by 0.9 mm the other).
struct StanfordConfEntry {
  std::string name;  // file name as written (relative to the .conf file's folder)
  Rigid3d world_from_scan;
  int line = 0;
};

// Reads a .conf file. `camera` lines (the viewer's camera) are accepted and ignored; any other
// keyword, a wrong number of values, a non-number or a quaternion far from unit length is an Error
// naming the file and line.
std::vector<StanfordConfEntry> ReadStanfordConf(const std::string& path);

// Moves points and normals by the transform.
void TransformMesh(const Rigid3d& target_from_source, ScanMesh* mesh);

}  // namespace ibrdf
