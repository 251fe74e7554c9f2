#include "spatial/material_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include <nanoflann.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/kind.h"
#include "core/logging.h"
#include "scan/mesh_file.h"
#include "scan/ply_io.h"
#include "spatial/uniformity.h"

namespace ibrdf {
namespace {

// Okabe and Ito's colour-blind-safe palette, one colour per basis (cycled beyond eight).
constexpr std::array<std::array<double, 3>, 8> kPalette = {{{230, 159, 0},
                                                          {86, 180, 233},
                                                          {0, 158, 115},
                                                          {240, 228, 66},
                                                          {0, 114, 178},
                                                          {213, 94, 0},
                                                          {204, 121, 167},
                                                          {0, 0, 0}}};

struct CentreCloud {
  std::vector<Eigen::Vector3d> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(size_t index, size_t dim) const { return points[index][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using CentreTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CentreCloud>, CentreCloud, 3, uint32_t>;

}  // namespace

std::string MaterialMeshResult::BriefReport() const {
  if (!written) return "materials.ply not written: " + not_written;
  const auto percent = [this](uint64_t n) { return Fixed(vertices ? 100.0 * double(n) / double(vertices) : 0.0, 1); };
  return "materials.ply: " + std::to_string(vertices) + " vertices, " + percent(own_cell) + " % weighted by their own cell, " +
         percent(near_cell) + " % by a near one, " + percent(none) + " % by none; " + percent(not_fitting) +
         " % in cells that fit no combination";
}

MaterialMeshResult WriteMaterialMesh(const Session& session, const MaterialWeightsResult& weights,
                                     const std::vector<int>& bases, const Eigen::Vector3d& origin, double cell_m,
                                     const std::string& path, VertexMaterials* vertices) {
  MaterialMeshResult result;
  switch (session.sample.kind) {
    case SampleSpec::Kind::kSphere:
    case SampleSpec::Kind::kCylinder:
      result.not_written = "an analytic sample has no mesh (the cells' weights are in materials.json)";
      return result;
    case SampleSpec::Kind::kMesh:
      break;
  }
  const std::string file = ResolvePath(session.directory, session.sample.mesh_file);
  ScanMesh mesh = ReadTriangleMeshFile(file);
  const size_t n = mesh.points.size();
  for (Eigen::Vector3d& p : mesh.points) p = session.sample.world_from_mesh * p;
  std::vector<Eigen::Vector3d> normals = std::move(mesh.normals);
  mesh.ClearPointData();
  if (normals.size() == n) {
    for (Eigen::Vector3d& normal : normals) normal = session.sample.world_from_mesh.rotation * normal;
    mesh.normals = std::move(normals);
  }

  std::unordered_map<uint64_t, size_t> cell_of_key;
  CentreCloud centres;
  std::vector<size_t> centre_cell;
  for (size_t c = 0; c < weights.cells.size(); ++c) {
    if (!weights.cells[c].fitted) continue;
    cell_of_key.emplace(weights.cells[c].key, c);
    centres.points.push_back(weights.cells[c].centre);
    centre_cell.push_back(c);
  }
  CentreTree tree(3, centres, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  if (!centres.points.empty()) tree.buildIndex();
  const double max_distance_sq = (1.5 * cell_m) * (1.5 * cell_m);

  const size_t n_bases = bases.size();
  std::vector<PlyVertexProperty> properties;
  properties.push_back({"label", PlyPropertyType::kInt, std::vector<double>(n, -1.0)});
  for (size_t b = 0; b < n_bases; ++b) {
    properties.push_back(
        {"weight_group_" + std::to_string(bases[b]), PlyPropertyType::kFloat, std::vector<double>(n, 0.0)});
  }
  properties.push_back({"residual", PlyPropertyType::kFloat, std::vector<double>(n, -1.0)});
  properties.push_back({"fits", PlyPropertyType::kUchar, std::vector<double>(n, 0.0)});
  properties.push_back({"weights_from", PlyPropertyType::kUchar, std::vector<double>(n, 0.0)});
  properties.push_back({"weight_sum", PlyPropertyType::kFloat, std::vector<double>(n, 0.0)});
  for (const char* colour : {"red", "green", "blue"}) {
    properties.push_back({colour, PlyPropertyType::kUchar, std::vector<double>(n, 128.0)});
  }
  const size_t residual = 1 + n_bases, fits = residual + 1, from = fits + 1, weight_sum = from + 1,
               red = weight_sum + 1;
  result.vertices = n;
  for (size_t v = 0; v < n; ++v) {
    const Eigen::Vector3d& p = mesh.points[v];
    const CellWeights* cell = nullptr;
    VertexWeightsFrom source = VertexWeightsFrom::kNone;
    const auto it = cell_of_key.find(UniformityCellKey(p, origin, cell_m));
    if (it != cell_of_key.end()) {
      cell = &weights.cells[it->second];
      source = VertexWeightsFrom::kOwnCell;
    } else if (!centres.points.empty()) {
      uint32_t index = 0;
      double distance_sq = 0.0;
      tree.knnSearch(p.data(), 1, &index, &distance_sq);
      if (distance_sq <= max_distance_sq) {
        cell = &weights.cells[centre_cell[index]];
        source = VertexWeightsFrom::kNearCell;
      }
    }
    properties[from].values[v] = double(static_cast<uint8_t>(source));
    switch (source) {
      case VertexWeightsFrom::kOwnCell: ++result.own_cell; break;
      case VertexWeightsFrom::kNearCell: ++result.near_cell; break;
      case VertexWeightsFrom::kNone: ++result.none; break;
    }
    if (!cell) continue;
    const double sum = cell->weights.sum();
    properties[0].values[v] = double(bases[size_t(cell->dominant)]);
    Eigen::Vector3d colour = Eigen::Vector3d::Zero();
    for (size_t b = 0; b < n_bases; ++b) {
      const double w = sum > 0.0 ? cell->weights[Eigen::Index(b)] / sum : 0.0;
      properties[1 + b].values[v] = w;
      for (int k = 0; k < 3; ++k) colour[k] += w * kPalette[b % kPalette.size()][size_t(k)];
    }
    properties[weight_sum].values[v] = sum;
    properties[residual].values[v] = cell->rel_rms;
    properties[fits].values[v] = cell->fits ? 1.0 : 0.0;
    if (!cell->fits) {
      ++result.not_fitting;
      colour = Eigen::Vector3d(255, 0, 255);
    }
    for (int k = 0; k < 3; ++k) properties[red + size_t(k)].values[v] = colour[k];
  }
  if (vertices) {
    vertices->bases = bases;
    vertices->weights = Eigen::MatrixXd::Zero(Eigen::Index(n), Eigen::Index(n_bases));
    vertices->label.assign(n, -1);
    vertices->fits.assign(n, 0);
    vertices->from.assign(n, VertexWeightsFrom::kNone);
    vertices->scale.assign(n, 0.0);
    for (size_t v = 0; v < n; ++v) {
      vertices->scale[v] = properties[weight_sum].values[v];
      for (size_t b = 0; b < n_bases; ++b) vertices->weights(Eigen::Index(v), Eigen::Index(b)) = properties[1 + b].values[v];
      vertices->label[v] = int(properties[0].values[v]);
      vertices->fits[v] = uint8_t(properties[fits].values[v]);
      vertices->from[v] = static_cast<VertexWeightsFrom>(uint8_t(properties[from].values[v]));
    }
  }
  WritePly(path, mesh, properties,
           "ibrdf materials: the mesh in the world frame (metres) with each vertex's weights over the measured "
           "groups (docs/spatial.md)");
  result.written = true;
  if (vertices) vertices->mesh = std::move(mesh);
  return result;
}

}  // namespace ibrdf
