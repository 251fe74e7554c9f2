// Cleaning of a scan mesh, step by step, each step counted: statistical outliers (PCL), duplicate
// vertices, degenerate and tiny faces, non-manifold faces (OpenMesh refuses them), small disconnected
// pieces, and points no face uses.
#pragma once

#include <cstdint>
#include <string>

#include "core/logging.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

struct CleanOptions {
  // Statistical outliers (PCL StatisticalOutlierRemoval): a point whose mean distance to its
  // outlier_neighbours nearest points exceeds the global mean by outlier_stddev standard deviations.
  bool remove_outliers = true;
  int outlier_neighbours = 16;
  double outlier_stddev = 4.0;
  // Points closer than this are one point (metres; 0: exact duplicates only).
  double duplicate_distance_m = 1e-7;
  // A face whose area is below this fraction of the median face area is tiny and removed.
  double tiny_face_fraction = 1e-4;
  // A connected piece with fewer faces than this fraction of all faces is removed (0: keep all).
  double min_piece_fraction = 0.005;
  // Points that no face uses are removed (the output is a surface; normals need one).
  bool remove_unreferenced = true;

  bool Check(std::string* why) const;
};

struct CleanReport {
  uint64_t points_in = 0, faces_in = 0, points_out = 0, faces_out = 0;
  // Removed items by step: outlier_points, duplicate_points, degenerate_faces (repeated corner, zero
  // area, or the same corners as another face), tiny_faces, non_manifold_faces, small_piece_faces,
  // unreferenced_points, plus faces_of_removed_points.
  RejectionCounts removed;
  uint64_t pieces = 0;  // connected pieces left
  double seconds = 0.0;
  // "clean: 40256 -> 40100 points, 76000 -> 75800 faces; removed outlier_points 12, ..."
  std::string BriefReport() const;
};

// Cleans the mesh in place (the steps in the order listed above) and reports what went.
CleanReport CleanMesh(const CleanOptions& options, ScanMesh* mesh);

}  // namespace ibrdf
