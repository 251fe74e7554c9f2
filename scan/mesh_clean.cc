#include "scan/mesh_clean.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/statistics.h"
#include "scan/adapters.h"
#include "scan/point_index.h"

namespace ibrdf {
namespace {

// Drops faces where keep[f] is false; returns how many went.
uint64_t KeepFaces(const std::vector<bool>& keep, ScanMesh* mesh) {
  size_t out = 0;
  for (size_t i = 0; i < mesh->faces.size(); ++i) {
    if (keep[i]) mesh->faces[out++] = mesh->faces[i];
  }
  const uint64_t removed = mesh->faces.size() - out;
  mesh->faces.resize(out);
  return removed;
}

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

}  // namespace

bool CleanOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(outlier_neighbours, 1);
  IBRDF_CHECK_OPTION_GT(outlier_stddev, 0.0);
  IBRDF_CHECK_OPTION_GE(duplicate_distance_m, 0.0);
  IBRDF_CHECK_OPTION_GE(tiny_face_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(tiny_face_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(min_piece_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(min_piece_fraction, 1.0);
  return true;
}

std::string CleanReport::BriefReport() const {
  std::ostringstream out;
  out << "clean: " << points_in << " -> " << points_out << " points, " << faces_in << " -> " << faces_out << " faces, "
      << pieces << " pieces; removed " << FormatCounts(removed);
  return out.str();
}

CleanReport CleanMesh(const CleanOptions& options, ScanMesh* mesh) {
  std::string why;
  IBRDF_CHECK(options.Check(&why)) << why;
  const Timer timer;
  CleanReport report;
  report.points_in = mesh->points.size();
  report.faces_in = mesh->faces.size();
  auto& removed = report.removed;
  for (const char* key : {"outlier_points", "duplicate_points", "degenerate_faces", "tiny_faces", "non_manifold_faces",
                          "small_piece_faces", "unreferenced_points", "faces_of_removed_points"}) {
    removed[key] = 0;
  }

  // 1. Statistical outliers.
  if (options.remove_outliers && mesh->points.size() > static_cast<size_t>(options.outlier_neighbours)) {
    const std::vector<bool> keep =
        scan_adapters::StatisticalInliers(mesh->points, options.outlier_neighbours, options.outlier_stddev);
    removed["outlier_points"] += std::count(keep.begin(), keep.end(), false);
    removed["faces_of_removed_points"] += KeepPoints(keep, mesh);
  }

  // 2. Duplicate points: each point within duplicate_distance_m of an earlier kept point merges into it.
  {
    std::vector<int> target(mesh->points.size());
    std::iota(target.begin(), target.end(), 0);
    std::vector<bool> keep(mesh->points.size(), true);
    if (!mesh->points.empty()) {
      const PointIndex index(mesh->points);
      std::vector<int> near;
      for (size_t i = 0; i < mesh->points.size(); ++i) {
        if (!keep[i]) continue;
        index.RadiusSearch(mesh->points[i], options.duplicate_distance_m, &near);
        for (int j : near) {
          if (j > static_cast<int>(i) && keep[j] &&
              (mesh->points[j] - mesh->points[i]).norm() <= options.duplicate_distance_m) {
            keep[j] = false;
            target[j] = static_cast<int>(i);
          }
        }
      }
    }
    const uint64_t duplicates = std::count(keep.begin(), keep.end(), false);
    if (duplicates > 0) {
      for (Eigen::Vector3i& f : mesh->faces) {
        for (int k = 0; k < 3; ++k) f[k] = target[f[k]];
      }
      removed["duplicate_points"] += duplicates;
      KeepPoints(keep, mesh);  // no face uses a merged point any more
    }
  }

  // 3. Degenerate faces (a repeated corner, zero area, or the same corners as an earlier face) and
  // tiny faces.
  if (!mesh->faces.empty()) {
    std::vector<bool> keep(mesh->faces.size(), true);
    std::vector<double> areas(mesh->faces.size());
    std::set<std::array<int, 3>> seen;
    uint64_t degenerate = 0;
    for (size_t i = 0; i < mesh->faces.size(); ++i) {
      const Eigen::Vector3i& f = mesh->faces[i];
      areas[i] = FaceArea(*mesh, i);
      std::array<int, 3> key = {f[0], f[1], f[2]};
      std::sort(key.begin(), key.end());
      if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || !(areas[i] > 0.0) || !seen.insert(key).second) {
        keep[i] = false;
        ++degenerate;
      }
    }
    std::vector<double> valid;
    for (size_t i = 0; i < areas.size(); ++i) {
      if (keep[i]) valid.push_back(areas[i]);
    }
    uint64_t tiny = 0;
    if (!valid.empty() && options.tiny_face_fraction > 0.0) {
      const double limit = options.tiny_face_fraction * PercentileInPlace(&valid, 0.5);
      for (size_t i = 0; i < areas.size(); ++i) {
        if (keep[i] && areas[i] < limit) {
          keep[i] = false;
          ++tiny;
        }
      }
    }
    KeepFaces(keep, mesh);
    removed["degenerate_faces"] += degenerate;
    removed["tiny_faces"] += tiny;
  }

  // 4. Non-manifold faces: OpenMesh's half-edge structure refuses a face that would make an edge or a
  // vertex non-manifold.
  if (!mesh->faces.empty()) {
    removed["non_manifold_faces"] += KeepFaces(scan_adapters::ManifoldFaces(*mesh), mesh);
  }

  // 5. Small pieces: connected components over shared vertices (union-find).
  if (!mesh->faces.empty()) {
    std::vector<int> parent(mesh->points.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (const Eigen::Vector3i& f : mesh->faces) {
      const int a = Find(parent, f[0]);
      parent[Find(parent, f[1])] = a;
      parent[Find(parent, f[2])] = a;
    }
    std::vector<uint64_t> piece_faces(mesh->points.size(), 0);
    for (const Eigen::Vector3i& f : mesh->faces) ++piece_faces[Find(parent, f[0])];
    const double limit = options.min_piece_fraction * static_cast<double>(mesh->faces.size());
    std::vector<bool> keep(mesh->faces.size(), true);
    for (size_t i = 0; i < mesh->faces.size(); ++i) {
      keep[i] = static_cast<double>(piece_faces[Find(parent, mesh->faces[i][0])]) >= limit;
    }
    removed["small_piece_faces"] += KeepFaces(keep, mesh);
    std::set<int> roots;
    for (const Eigen::Vector3i& f : mesh->faces) roots.insert(Find(parent, f[0]));
    report.pieces = roots.size();
  }

  // 6. Unreferenced points.
  if (options.remove_unreferenced) {
    std::vector<bool> used(mesh->points.size(), false);
    for (const Eigen::Vector3i& f : mesh->faces) used[f[0]] = used[f[1]] = used[f[2]] = true;
    removed["unreferenced_points"] += std::count(used.begin(), used.end(), false);
    KeepPoints(used, mesh);
  }

  mesh->grid = RangeGrid();  // cleaning renumbers points; the grid no longer describes them
  report.points_out = mesh->points.size();
  report.faces_out = mesh->faces.size();
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace ibrdf
