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
#include <CGAL/Convex_hull_traits_3.h>
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
// The hull's traits with CGAL's filtered plane predicate (exact where the filter fails). CGAL's
// triangle-soup overload of convex_hull_3 takes the kernel itself as its traits, whose planes are
// inexact constructions: on near-coplanar points (a torus far from the origin) it dropped hull
// vertices and gave distances wrong by 0.7 mm. The Surface_mesh overload uses these
// traits, but copying the hull into a halfedge mesh cost a third of the time.
using HullTraits = CGAL::Convex_hull_traits_3<Kernel, CGAL::Default, CGAL::Tag_true>;
using HullPoints = std::vector<Point>;
using HullTriangles = std::vector<std::array<std::size_t, 3>>;
using HullSoup = CGAL::Convex_hull_3::internal::Indexed_triangle_set<HullPoints, HullTriangles>;

struct PointHash {
  size_t operator()(const Point& p) const {
    const std::hash<double> h;
    return h(p.x()) ^ (h(p.y()) * 0x9e3779b97f4a7c15ull) ^ (h(p.z()) * 0xc2b2ae3d27d4eb4full);
  }
};

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
  HullPoints hull_points;
  HullTriangles hull_triangles;
  HullSoup soup(hull_points, hull_triangles);
  CGAL::convex_hull_3(centred.begin(), centred.end(), soup, HullTraits());
  // Fewer than 4 hull vertices: the points are coplanar or collinear and span no volume.
  if (hull_triangles.size() < 4 || hull_points.size() < 4) return result;
  result.hull_vertices = hull_points.size();
  result.hull_faces = hull_triangles.size();
  // The hull's vertices are input points (copied exactly), on its surface: distance 0, no query. On a
  // convex sample that is most points, so only the others are measured.
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
    // Built here, before the queries share it across threads (queries on a built tree only read).
    tree.build();
    tree.accelerate_distance_queries();
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
