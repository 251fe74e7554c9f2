#include "scan/scan_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/file_util.h"
#include "scan/adapters.h"
#include "scan/ply_io.h"

namespace ibrdf {

ScanMesh ReadScanFile(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply") return ReadPly(path);
  if (extension == ".obj" || extension == ".off" || extension == ".stl") return scan_adapters::ReadMeshFile(path);
  if (extension == ".pcd") return scan_adapters::ReadPcdFile(path);
  ThrowError(path, "unsupported scan format '" + extension + "' (expected .ply, .obj, .off, .stl or .pcd)");
}

std::vector<StanfordConfEntry> ReadStanfordConf(const std::string& path) {
  RequireFile(path, "scan configuration");
  std::ifstream in(path);
  if (!in) ThrowError(path, "cannot open for reading");
  std::vector<StanfordConfEntry> entries;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string where = path + ": line " + std::to_string(line_number);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword) || keyword[0] == '#') continue;
    std::vector<std::string> rest;
    std::string word;
    while (words >> word) rest.push_back(word);
    auto numbers = [&](size_t first, size_t count) {
      if (rest.size() != first + count) {
        ThrowError(where, "'" + keyword + "' expects " + std::to_string(first + count) + " values, got " +
                              std::to_string(rest.size()));
      }
      std::vector<double> values;
      for (size_t i = first; i < rest.size(); ++i) {
        char* end = nullptr;
        const double v = std::strtod(rest[i].c_str(), &end);
        if (*end != '\0' || end == rest[i].c_str() || !std::isfinite(v)) {
          ThrowError(where, "'" + rest[i] + "' is not a finite number");
        }
        values.push_back(v);
      }
      return values;
    };
    if (keyword == "camera") {
      numbers(0, 7);
    } else if (keyword == "bmesh") {
      const std::vector<double> v = numbers(1, 7);
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // Eigen's order is (w, x, y, z)
      if (std::abs(q.norm() - 1.0) > 1e-3) {
        ThrowError(where,
                   "the quaternion (qx qy qz qw) is not of unit length (|q| = " + std::to_string(q.norm()) + ")");
      }
      StanfordConfEntry entry;
      entry.name = rest[0];
      // The quaternion as scanalyze writes it rotates the common frame into the scan's, so the scan's
      // points move by its inverse: with R(q) itself, bun045 misses bun000 by 0.9 mm where they
      // overlap; with R(q)^-1 the median gap is 0.09 mm (tests/scan/scan_io_test.cc).
      entry.world_from_scan = Rigid3d(q.normalized().conjugate(), Eigen::Vector3d(v[0], v[1], v[2]));
      entry.line = line_number;
      entries.push_back(entry);
    } else {
      ThrowError(where, "unknown keyword '" + keyword + "' (expected 'camera' or 'bmesh')");
    }
  }
  if (entries.empty()) ThrowError(path, "no 'bmesh' lines");
  return entries;
}

void TransformMesh(const Rigid3d& target_from_source, ScanMesh* mesh) {
  for (Eigen::Vector3d& p : mesh->points) p = target_from_source * p;
  for (Eigen::Vector3d& n : mesh->normals) n = target_from_source.rotation * n;
}

}  // namespace ibrdf
