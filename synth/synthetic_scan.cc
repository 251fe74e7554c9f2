#include "synth/synthetic_scan.h"

#include <cmath>
#include <fstream>
#include <random>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/file_util.h"

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
      const Eigen::Vector3d normal =
          Eigen::Vector3d(x / (r.x() * r.x()), y / (r.y() * r.y()), z / (r.z() * r.z())).normalized();
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

bool RangeScannerOptions::Check(std::string* why) const {
  if (views_around < 0 || (views_around == 0 && !view_above)) {
    *why = "the scanner needs at least one view";
    return false;
  }
  if (!(std::abs(around_elevation_deg) < 89.0)) {
    *why = "around_elevation_deg must be in (-89, 89)";
    return false;
  }
  if (!(distance_m > 0.0) || !(spacing_m > 0.0) || !(spacing_m < distance_m)) {
    *why = "distance_m and spacing_m must be positive, the spacing below the distance";
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

std::vector<ScanMesh> SimulateRangeScans(const RayCaster& surface, const Eigen::Vector3d& center, double radius,
                                         const RangeScannerOptions& options, const Rigid3d& scan_from_world) {
  std::string why;
  if (!options.Check(&why)) ThrowError("simulated range scan", why);
  IBRDF_CHECK(radius > 0.0 && radius < options.distance_m) << "the scanner must be outside the sample";
  const double degree = M_PI / 180.0;
  const double cos_limit = std::cos(options.max_view_angle_deg * degree);
  // The grid covers the sample's bounding sphere.
  const double cell = options.spacing_m / options.distance_m;  // on the normalized image plane
  const double half_extent = std::tan(std::asin(radius / options.distance_m));
  const int size = 2 * static_cast<int>(std::ceil(half_extent / cell)) + 1;
  std::vector<ScanMesh> views;
  const int num_views = options.views_around + (options.view_above ? 1 : 0);
  for (int v = 0; v < num_views; ++v) {
    Eigen::Vector3d direction, up = Eigen::Vector3d::UnitZ();
    if (v < options.views_around) {
      const double azimuth = 2.0 * M_PI * v / options.views_around;
      const double elevation = options.around_elevation_deg * degree;
      direction = Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                  std::sin(elevation));
    } else {
      direction = Eigen::Vector3d::UnitZ();
      up = Eigen::Vector3d::UnitY();
    }
    const Eigen::Vector3d scanner = center + options.distance_m * direction;
    const Rigid3d world_from_scanner = LookAtCameraFromWorld(scanner, center, up).Inverse();
    const Eigen::Matrix3d rotation = world_from_scanner.rotation.toRotationMatrix();
    // Rows in parallel, each with its own random stream (seed, view, row).
    std::vector<std::vector<std::pair<int, Eigen::Vector3d>>> rows(size);
    tbb::parallel_for(0, size, [&](int row) {
      std::mt19937_64 random(options.seed * 0x9E3779B97F4A7C15ull + (uint64_t(v) << 32) + uint64_t(row));
      std::normal_distribution<double> noise(0.0, 1.0);
      for (int col = 0; col < size; ++col) {
        const Eigen::Vector3d ray =
            (rotation * Eigen::Vector3d((col + 0.5 - 0.5 * size) * cell, (row + 0.5 - 0.5 * size) * cell, 1.0))
                .normalized();
        double t;
        Eigen::Vector3d normal;
        if (!surface(scanner, ray, &t, &normal)) continue;
        if (-ray.dot(normal) < cos_limit) continue;  // too oblique: the scanner returns nothing
        const double range = t + options.noise_m * noise(random);
        rows[row].emplace_back(col, scan_from_world * (scanner + range * ray));
      }
    });
    ScanMesh mesh;
    mesh.grid.rows = size;
    mesh.grid.cols = size;
    mesh.grid.cell_point.assign(static_cast<size_t>(size) * size, -1);
    for (int row = 0; row < size; ++row) {
      for (const auto& [col, point] : rows[row]) {
        mesh.grid.cell_point[static_cast<size_t>(row) * size + col] = static_cast<int>(mesh.points.size());
        mesh.points.push_back(point);
      }
    }
    views.push_back(std::move(mesh));
  }
  return views;
}

void WriteRangeGridPly(const std::string& path, const ScanMesh& grid) {
  IBRDF_CHECK(!grid.grid.Empty() && grid.grid.cell_point.size() == size_t(grid.grid.rows) * grid.grid.cols)
      << "not a range grid";
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot open for writing");
    out << "ply\nformat binary_little_endian 1.0\ncomment ibrdf synth: simulated range scan (metres, scanner frame)\n";
    out << "obj_info num_cols " << grid.grid.cols << "\nobj_info num_rows " << grid.grid.rows << "\n";
    out << "element vertex " << grid.points.size() << "\nproperty double x\nproperty double y\nproperty double z\n";
    out << "element range_grid " << grid.grid.cell_point.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&out](const auto& value) { out.write(reinterpret_cast<const char*>(&value), sizeof(value)); };
    for (const Eigen::Vector3d& p : grid.points) {
      for (int k = 0; k < 3; ++k) put(p[k]);
    }
    for (const int index : grid.grid.cell_point) {
      if (index < 0) {
        put(uint8_t{0});
      } else {
        put(uint8_t{1});
        put(static_cast<int32_t>(index));
      }
    }
    if (!out) ThrowError(path, "write failed");
  }
  file.Commit();
}

}  // namespace ibrdf
