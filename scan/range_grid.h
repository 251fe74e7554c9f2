// Tessellation of a range image by its grid neighbours (Turk and Levoy 1994, "Zippered polygon
// meshes", section 3): each 2x2 block of cells gives two triangles, split along the shorter diagonal,
// or one where a cell is empty. A triangle with an edge much longer than the grid spacing spans a
// depth discontinuity (a silhouette, or a surface seen at grazing) and is dropped.
#pragma once

#include <cstdint>
#include <string>

#include "scan/scan_mesh.h"

namespace ibrdf {

struct RangeGridOptions {
  // A triangle is dropped when one of its edges is longer than max_edge_factor times the grid's median
  // neighbour spacing (4: a surface tilted up to about 75 degrees from the scanner is kept).
  double max_edge_factor = 4.0;
  // An absolute edge limit in metres, used instead of the factor when > 0.
  double max_edge_m = 0.0;

  bool Check(std::string* why) const;
};

struct RangeGridReport {
  uint64_t cells = 0;                        // grid cells
  uint64_t points = 0;                       // cells holding a point
  uint64_t triangles = 0;                    // triangles kept
  uint64_t dropped_depth_discontinuity = 0;  // triangles with an over-long edge
  double spacing_m = 0.0;                    // median grid-neighbour distance
  double max_edge_used_m = 0.0;
  // "range grid 512x400: 40256 points, 76000 triangles, 1234 dropped across depth discontinuities"
  std::string BriefReport() const;
  int rows = 0, cols = 0;
};

// Replaces mesh->faces by the grid's triangles, oriented outward (OrientFacesOutward). The mesh must
// hold a range grid (mesh->grid); the grid is kept. Throws InternalError without one.
RangeGridReport TessellateRangeGrid(const RangeGridOptions& options, ScanMesh* mesh);

// Flips every face when, summed over faces (area-weighted), the normals point towards the centroid of
// the points rather than away from it: "outward" for a sample seen from outside. Returns true if it
// flipped.
bool OrientFacesOutward(ScanMesh* mesh);

}  // namespace ibrdf
