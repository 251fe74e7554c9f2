#include "scan/mesh_file.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.h"
#include "scan/adapters.h"
#include "scan/ply_io.h"

namespace ibrdf {

ScanMesh ReadTriangleMeshFile(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply") return ReadPly(path);
  if (extension == ".obj" || extension == ".off" || extension == ".stl") return scan_adapters::ReadMeshFile(path);
  if (extension == ".pcd") {
    ThrowError(path,
               "is a point cloud (no faces); the derenderer intersects rays with a triangle mesh: run "
               "`ibrdf scan` on it, which reconstructs one");
  }
  ThrowError(path, "unsupported mesh format '" + extension + "' (expected .ply, .obj, .off or .stl)");
}

std::string ScanSidecarPath(const std::string& ply_path) { return ply_path + ".json"; }

}  // namespace ibrdf
