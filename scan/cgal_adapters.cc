// CGAL, in this one translation unit (it compiles slowly).
#include <array>
#include <cmath>
#include <functional>
#include <unordered_set>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_3.h>

#include "scan/adapters.h"

namespace ibrdf::scan_adapters {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TrianglePrimitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, TrianglePrimitive>>;

std::vector<Point> CentredPoints(const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d centre = Centroid(points);
  std::vector<Point> out;
  out.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p - centre;
    out.emplace_back(q.x(), q.y(), q.z());
  }
  return out;
}
}  // namespace

std::vector<Eigen::Vector3i> AdvancingFrontReconstruction(const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3i> faces;
  if (points.size() < 3) return faces;
  const std::vector<Point> centred = CentredPoints(points);
  std::vector<std::array<std::size_t, 3>> facets;
  CGAL::advancing_front_surface_reconstruction(centred.begin(), centred.end(), std::back_inserter(facets));
  faces.reserve(facets.size());
  for (const auto& f : facets) {
    faces.emplace_back(static_cast<int>(f[0]), static_cast<int>(f[1]), static_cast<int>(f[2]));
  }
  return faces;
}

HullDistances ConvexHullDistances(const std::vector<Eigen::Vector3d>& points) {
  HullDistances result;
  if (points.size() < 4) return result;
  const std::vector<Point> centred = CentredPoints(points);
  // The hull as an indexed triangle set (no halfedge structure to build and copy).
  std::vector<Point> hull_points;
  std::vector<std::array<std::size_t, 3>> hull_triangles;
  CGAL::convex_hull_3(centred.begin(), centred.end(), hull_points, hull_triangles);
  // Fewer than 4 hull vertices: the points are coplanar or collinear and span no volume.
  if (hull_triangles.size() < 4 || hull_points.size() < 4) return result;
  result.hull_vertices = hull_points.size();
  result.hull_faces = hull_triangles.size();
  // The hull's vertices are input points, on its surface: distance 0, no query. On a convex sample
  // that is nearly every point, so only the few inside are measured.
  struct PointHash {
    size_t operator()(const Point& p) const {
      const std::hash<double> h;
      return h(p.x()) ^ (h(p.y()) * 0x9e3779b97f4a7c15ull) ^ (h(p.z()) * 0xc2b2ae3d27d4eb4full);
    }
  };
  const std::unordered_set<Point, PointHash> on_hull(hull_points.begin(), hull_points.end());
  result.distance_m.assign(points.size(), 0.0);
  std::vector<size_t> inside;
  for (size_t i = 0; i < centred.size(); ++i) {
    if (!on_hull.count(centred[i])) inside.push_back(i);
  }
  if (!inside.empty()) {
    std::vector<Triangle> triangles;
    triangles.reserve(hull_triangles.size());
    for (const auto& t : hull_triangles)
      triangles.emplace_back(hull_points[t[0]], hull_points[t[1]], hull_points[t[2]]);
    TriangleTree tree(triangles.begin(), triangles.end());
    tree.accelerate_distance_queries();
    // Queries on a built tree are read-only: one per point, across threads.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, inside.size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k < range.end(); ++k) {
        const size_t i = inside[k];
        result.distance_m[i] = std::sqrt(CGAL::to_double(tree.squared_distance(centred[i])));
      }
    });
  }
  result.valid = true;
  return result;
}

}  // namespace ibrdf::scan_adapters
