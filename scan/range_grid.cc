#include "scan/range_grid.h"

#include <algorithm>
#include <sstream>

#include "core/error.h"
#include "core/statistics.h"

namespace ibrdf {

bool RangeGridOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(max_edge_factor, 1.0);  // a factor of the grid spacing
  IBRDF_CHECK_OPTION_GE(max_edge_m, 0.0);       // 0: use the factor
  return true;
}

std::string RangeGridReport::BriefReport() const {
  std::ostringstream out;
  out << "range grid " << cols << "x" << rows << ": " << points << " points, " << triangles << " triangles, "
      << dropped_depth_discontinuity << " dropped across depth discontinuities (edge > " << max_edge_used_m * 1e3
      << " mm, spacing " << spacing_m * 1e3 << " mm)";
  return out.str();
}

RangeGridReport TessellateRangeGrid(const RangeGridOptions& options, ScanMesh* mesh) {
  std::string why;
  IBRDF_CHECK(options.Check(&why)) << why;
  const RangeGrid& grid = mesh->grid;
  IBRDF_CHECK(!grid.Empty()) << "the mesh holds no range grid";
  RangeGridReport report;
  report.rows = grid.rows;
  report.cols = grid.cols;
  report.cells = grid.cell_point.size();
  for (int v : grid.cell_point) report.points += v >= 0;

  auto distance = [&](int a, int b) { return (mesh->points[a] - mesh->points[b]).norm(); };
  std::vector<double> spacing;
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      const int v = grid.At(r, c);
      if (v < 0) continue;
      if (c + 1 < grid.cols && grid.At(r, c + 1) >= 0) spacing.push_back(distance(v, grid.At(r, c + 1)));
      if (r + 1 < grid.rows && grid.At(r + 1, c) >= 0) spacing.push_back(distance(v, grid.At(r + 1, c)));
    }
  }
  if (!spacing.empty()) {
    report.spacing_m = PercentileInPlace(&spacing, 0.5);
  }
  const double max_edge = options.max_edge_m > 0.0 ? options.max_edge_m : options.max_edge_factor * report.spacing_m;
  report.max_edge_used_m = max_edge;

  mesh->faces.clear();
  auto add = [&](int a, int b, int c) {
    if (distance(a, b) > max_edge || distance(b, c) > max_edge || distance(c, a) > max_edge) {
      ++report.dropped_depth_discontinuity;
      return;
    }
    mesh->faces.emplace_back(a, b, c);
  };
  for (int r = 0; r + 1 < grid.rows; ++r) {
    for (int c = 0; c + 1 < grid.cols; ++c) {
      // Corners in image order: a b / d e (counter-clockwise in (col, row) is a, d, e, b).
      const int a = grid.At(r, c), b = grid.At(r, c + 1), d = grid.At(r + 1, c), e = grid.At(r + 1, c + 1);
      const int valid = (a >= 0) + (b >= 0) + (d >= 0) + (e >= 0);
      if (valid == 4) {
        if (distance(a, e) <= distance(b, d)) {
          add(a, d, e);
          add(a, e, b);
        } else {
          add(a, d, b);
          add(b, d, e);
        }
      } else if (valid == 3) {
        if (a < 0) add(b, d, e);
        if (b < 0) add(a, d, e);
        if (d < 0) add(a, e, b);
        if (e < 0) add(a, d, b);
      }
    }
  }
  report.triangles = mesh->faces.size();
  OrientFacesOutward(mesh);
  return report;
}

bool OrientFacesOutward(ScanMesh* mesh) {
  if (mesh->faces.empty()) return false;
  const Eigen::Vector3d centre = Centroid(mesh->points);
  double vote = 0.0;
  for (const Eigen::Vector3i& f : mesh->faces) {
    const Eigen::Vector3d& a = mesh->points[f[0]];
    const Eigen::Vector3d n = (mesh->points[f[1]] - a).cross(mesh->points[f[2]] - a);  // area-weighted
    const Eigen::Vector3d face_centre = (a + mesh->points[f[1]] + mesh->points[f[2]]) / 3.0 - centre;
    const double length = face_centre.norm();
    if (length > 0.0) vote += n.dot(face_centre) / length;
  }
  if (vote >= 0.0) return false;
  for (Eigen::Vector3i& f : mesh->faces) std::swap(f[1], f[2]);
  return true;
}

}  // namespace ibrdf
