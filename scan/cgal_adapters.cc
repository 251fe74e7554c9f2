// CGAL, in this one translation unit (it compiles slowly).
#include <array>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include "scan/adapters.h"

namespace ibrdf::scan_adapters {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

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
  Mesh hull;
  CGAL::convex_hull_3(centred.begin(), centred.end(), hull);
  // Fewer than 4 hull vertices: the points are coplanar or collinear and span no volume.
  if (hull.number_of_faces() < 4 || hull.number_of_vertices() < 4) return result;
  result.hull_vertices = hull.number_of_vertices();
  result.hull_faces = hull.number_of_faces();
  Tree tree(faces(hull).first, faces(hull).second, hull);
  tree.accelerate_distance_queries();
  result.distance_m.resize(points.size());
  for (size_t i = 0; i < centred.size(); ++i) {
    result.distance_m[i] = std::sqrt(CGAL::to_double(tree.squared_distance(centred[i])));
  }
  result.valid = true;
  return result;
}

}  // namespace ibrdf::scan_adapters
