// OpenMesh, in this one translation unit.
// GCC 12 reports a false maybe-uninitialized inside OpenMesh's property containers when they are
// instantiated here; the warning is silenced for this adapter only.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <filesystem>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "core/error.h"
#include "core/file_util.h"
#include "scan/adapters.h"

namespace ibrdf::scan_adapters {
namespace {
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;

// OpenMesh prints refusals and reader complaints to its own error stream; the callers report counts
// and Errors instead.
class QuietOpenMesh {
 public:
  QuietOpenMesh() {
    omerr().disable();
    omlog().disable();
  }
  ~QuietOpenMesh() {
    omerr().enable();
    omlog().enable();
  }
};
}  // namespace

ScanMesh ReadMeshFile(const std::string& path) {
  RequireFile(path, "scan file");
  if (std::filesystem::file_size(path) == 0) ThrowError(path, "empty file");
  TriMesh om;
  {
    QuietOpenMesh quiet;
    OpenMesh::IO::Options options;
    if (!OpenMesh::IO::read_mesh(om, path, options)) {
      ThrowError(path, "OpenMesh cannot read this file (malformed, or not OBJ/OFF/STL)");
    }
  }
  ScanMesh mesh;
  mesh.points.reserve(om.n_vertices());
  for (const auto& vh : om.vertices()) {
    const auto& p = om.point(vh);
    mesh.points.emplace_back(p[0], p[1], p[2]);
  }
  for (const auto& fh : om.faces()) {
    Eigen::Vector3i f;
    int k = 0;
    for (const auto& vh : om.fv_range(fh)) {
      if (k < 3) f[k] = vh.idx();
      ++k;
    }
    if (k == 3) mesh.faces.push_back(f);
  }
  if (mesh.points.empty()) ThrowError(path, "no vertices");
  RequireFinitePoints(mesh, path);
  return mesh;
}

std::vector<bool> ManifoldFaces(const ScanMesh& mesh) {
  QuietOpenMesh quiet;
  TriMesh om;
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(mesh.points.size());
  for (const Eigen::Vector3d& p : mesh.points)
    handles.push_back(
        om.add_vertex(TriMesh::Point(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()))));
  std::vector<bool> keep(mesh.faces.size(), true);
  for (size_t i = 0; i < mesh.faces.size(); ++i) {
    const Eigen::Vector3i& f = mesh.faces[i];
    const auto fh = om.add_face(handles[f[0]], handles[f[1]], handles[f[2]]);
    keep[i] = fh.is_valid();
  }
  return keep;
}

}  // namespace ibrdf::scan_adapters
