#include "scan/synthetic_scan.h"

#include <cmath>
#include <random>

#include "core/error.h"

namespace ibrdf {

bool SyntheticRangeScanOptions::Check(std::string* why) const {
  if (!(radii.minCoeff() > 0.0)) {
    *why = "radii must be > 0";
    return false;
  }
  if (cols < 2 || rows < 2) {
    *why = "the range image needs at least 2 x 2 cells";
    return false;
  }
  if (!(noise_m >= 0.0)) {
    *why = "noise_m must be >= 0";
    return false;
  }
  if (!(max_view_angle_deg > 0.0 && max_view_angle_deg < 90.0)) {
    *why = "max_view_angle_deg must be in (0, 90)";
    return false;
  }
  return true;
}

Eigen::Vector3d TrueEllipsoidNormal(const SyntheticRangeScanOptions& options, const Eigen::Vector3d& p) {
  const Eigen::Vector3d& r = options.radii;
  const double x = p.x() - options.origin.x(), y = p.y() - options.origin.y();
  const double s = std::max(0.0, 1.0 - x * x / (r.x() * r.x()) - y * y / (r.y() * r.y()));
  const double z = r.z() * std::sqrt(s);
  return Eigen::Vector3d(x / (r.x() * r.x()), y / (r.y() * r.y()), z / (r.z() * r.z())).normalized();
}

ScanMesh MakeSyntheticRangeScan(const SyntheticRangeScanOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("synthetic range scan", why);
  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  ScanMesh mesh;
  mesh.grid.rows = options.rows;
  mesh.grid.cols = options.cols;
  mesh.grid.cell_point.assign(static_cast<size_t>(options.rows) * options.cols, -1);
  const Eigen::Vector3d& r = options.radii;
  const double cos_limit = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  for (int row = 0; row < options.rows; ++row) {
    for (int col = 0; col < options.cols; ++col) {
      const double x = r.x() * (2.0 * (col + 0.5) / options.cols - 1.0);
      const double y = r.y() * (1.0 - 2.0 * (row + 0.5) / options.rows);
      const double s = 1.0 - x * x / (r.x() * r.x()) - y * y / (r.y() * r.y());
      if (s <= 0.0) continue;
      const double z = r.z() * std::sqrt(s);
      const Eigen::Vector3d normal = Eigen::Vector3d(x / (r.x() * r.x()), y / (r.y() * r.y()), z / (r.z() * r.z())).normalized();
      if (normal.z() < cos_limit) continue;
      const double dz = options.noise_m * noise(random);
      mesh.grid.cell_point[static_cast<size_t>(row) * options.cols + col] = static_cast<int>(mesh.points.size());
      mesh.points.push_back(options.origin + Eigen::Vector3d(x, y, z + dz));
    }
  }
  return mesh;
}

ScanMesh MakeUvEllipsoid(const Eigen::Vector3d& radii, int rings, int segments) {
  IBRDF_CHECK(rings >= 2 && segments >= 3) << rings << " x " << segments;
  ScanMesh mesh;
  auto add = [&](double theta, double phi) {
    const Eigen::Vector3d unit(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    mesh.points.push_back(radii.cwiseProduct(unit));
    mesh.normals.push_back(unit.cwiseQuotient(radii).normalized());
  };
  add(0.0, 0.0);  // north pole
  for (int i = 1; i <= rings; ++i) {
    for (int j = 0; j < segments; ++j) add(M_PI * i / (rings + 1), 2.0 * M_PI * j / segments);
  }
  add(M_PI, 0.0);  // south pole
  const int south = static_cast<int>(mesh.points.size()) - 1;
  auto at = [&](int ring, int segment) { return 1 + (ring - 1) * segments + (segment % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.faces.emplace_back(0, at(1, j), at(1, j + 1));
    mesh.faces.emplace_back(south, at(rings, j + 1), at(rings, j));
  }
  for (int i = 1; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      mesh.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return mesh;
}

ScanMesh MakeTorus(double major_radius_m, double minor_radius_m, int rings, int segments) {
  IBRDF_CHECK(rings >= 3 && segments >= 3 && major_radius_m > minor_radius_m) << "bad torus";
  ScanMesh mesh;
  for (int i = 0; i < rings; ++i) {
    const double u = 2.0 * M_PI * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double v = 2.0 * M_PI * j / segments;
      const Eigen::Vector3d normal(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
      const Eigen::Vector3d centre(major_radius_m * std::cos(u), major_radius_m * std::sin(u), 0.0);
      mesh.points.push_back(centre + minor_radius_m * normal);
      mesh.normals.push_back(normal);
    }
  }
  auto at = [&](int i, int j) { return (i % rings) * segments + (j % segments); };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      mesh.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return mesh;
}

void AddNormalNoise(double noise_m, uint64_t seed, ScanMesh* mesh) {
  IBRDF_CHECK(mesh->normals.size() == mesh->points.size()) << "the mesh needs normals";
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  for (size_t i = 0; i < mesh->points.size(); ++i) mesh->points[i] += noise(random) * mesh->normals[i];
}

}  // namespace ibrdf
