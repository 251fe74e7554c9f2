#include "scan/scan_mesh.h"

#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "core/error.h"

namespace ibrdf {

void ScanMesh::ClearPointData() {
  normals.clear();
  fit_rms_m.clear();
  fit_neighbours.clear();
  hull_distance_m.clear();
}

Eigen::Vector3d FaceNormal(const ScanMesh& mesh, size_t face) {
  const Eigen::Vector3i& f = mesh.faces[face];
  const Eigen::Vector3d& a = mesh.points[f[0]];
  // Edge vectors relative to the first corner: no loss of precision far from the origin.
  const Eigen::Vector3d n = (mesh.points[f[1]] - a).cross(mesh.points[f[2]] - a);
  const double length = n.norm();
  return length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
}

double FaceArea(const ScanMesh& mesh, size_t face) {
  const Eigen::Vector3i& f = mesh.faces[face];
  const Eigen::Vector3d& a = mesh.points[f[0]];
  return 0.5 * (mesh.points[f[1]] - a).cross(mesh.points[f[2]] - a).norm();
}

std::vector<Eigen::Vector3d> AreaWeightedVertexNormals(const ScanMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.points.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d& a = mesh.points[f[0]];
    const Eigen::Vector3d n = (mesh.points[f[1]] - a).cross(mesh.points[f[2]] - a);  // 2 x area
    for (int k = 0; k < 3; ++k) normals[f[k]] += n;
  }
  for (Eigen::Vector3d& n : normals) {
    const double length = n.norm();
    n = length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
  return normals;
}

std::vector<double> VertexAreas(const ScanMesh& mesh) {
  std::vector<double> areas(mesh.points.size(), 0.0);
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    const double third = FaceArea(mesh, i) / 3.0;
    for (int k = 0; k < 3; ++k) areas[mesh.faces[i][k]] += third;
  }
  return areas;
}

size_t KeepPoints(const std::vector<bool>& keep, ScanMesh* mesh) {
  IBRDF_CHECK(keep.size() == mesh->points.size()) << keep.size() << " vs " << mesh->points.size();
  std::vector<int> new_index(keep.size(), -1);
  size_t kept = 0;
  for (size_t i = 0; i < keep.size(); ++i) {
    if (keep[i]) new_index[i] = static_cast<int>(kept++);
  }
  auto filter = [&](auto& values) {
    if (values.size() != keep.size()) return;
    size_t out = 0;
    for (size_t i = 0; i < keep.size(); ++i) {
      if (keep[i]) values[out++] = values[i];
    }
    values.resize(out);
  };
  filter(mesh->points);
  filter(mesh->normals);
  filter(mesh->fit_rms_m);
  filter(mesh->fit_neighbours);
  filter(mesh->hull_distance_m);
  size_t dropped = 0, out = 0;
  for (const Eigen::Vector3i& f : mesh->faces) {
    const Eigen::Vector3i g(new_index[f[0]], new_index[f[1]], new_index[f[2]]);
    if (g.minCoeff() < 0) {
      ++dropped;
    } else {
      mesh->faces[out++] = g;
    }
  }
  mesh->faces.resize(out);
  if (!mesh->grid.Empty()) {
    for (int& cell : mesh->grid.cell_point) {
      if (cell >= 0) cell = new_index[cell];
    }
  }
  return dropped;
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return Eigen::Vector3d::Zero();
  // Two passes: a rough centre, then the mean offset from it, so the sum stays small far from the
  // origin.
  const Eigen::Vector3d rough = points.front();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p - rough;
  return rough + sum / static_cast<double>(points.size());
}

void RequireFinitePoints(const ScanMesh& mesh, const std::string& where) {
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    if (!mesh.points[i].allFinite()) {
      ThrowError(where, "vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
    }
    // Beyond this no scan of a sample lies (in metres, 1000 km; in millimetres, 1 km), and the later
    // arithmetic (centroids, ray distances) would overflow into "no photo sees the sample".
    constexpr double kMaxCoordinate = 1e6;
    if (mesh.points[i].cwiseAbs().maxCoeff() > kMaxCoordinate) {
      std::ostringstream point;
      point << mesh.points[i].transpose();
      ThrowError(where, "vertex " + std::to_string(i) + " lies at (" + point.str() +
                            "), beyond 1e6 in a coordinate: no scan of a sample (lengths are metres)");
    }
  }
  const int n = static_cast<int>(mesh.points.size());
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces[i][k];
      if (v < 0 || v >= n) {
        ThrowError(where, "face " + std::to_string(i) + " refers to vertex " + std::to_string(v) + ", but there are " +
                              std::to_string(n) + " vertices");
      }
    }
  }
}

}  // namespace ibrdf
