// The scanned mesh with each vertex's material: the cells' weights over the measured groups
// (material_weights.h) carried to the vertices, written as a PLY that mesh viewers colour and renderers
// read as vertex attributes (Mitsuba 3 reads extra PLY vertex properties as mesh attributes).
//
// Each vertex takes the weights of the cell that holds it (world frame, the uniformity check's grid),
// else of the nearest fitted cell within 1.5 cell edges (a vertex where the photos saw too few
// samples), else none: `weights_from` says which, so that no vertex's material is invented silently.
// An analytic sample (sphere, cylinder) has no mesh: nothing is written, and the reason is returned.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/session.h"
#include "scan/scan_mesh.h"
#include "spatial/material_weights.h"

namespace ibrdf {

// What weights_from holds per vertex.
enum class VertexWeightsFrom : uint8_t {
  kOwnCell = 0,      // the cell holding the vertex was fitted
  kNearCell = 1,     // the nearest fitted cell within 1.5 cell edges
  kNone = 2,         // no fitted cell near: label -1, weights 0
  IBRDF_DUMMY_KIND
};

struct MaterialMeshResult {
  bool written = false;
  std::string not_written;  // why, when not written
  uint64_t vertices = 0;
  uint64_t own_cell = 0, near_cell = 0, none = 0;  // vertices by VertexWeightsFrom
  uint64_t not_fitting = 0;                          // vertices whose cell fits no combination

  // "materials.ply: 35947 vertices, 81 % from their own cell, 12 % a near one, 7 % none; 2 % fit none"
  std::string BriefReport() const;
};

// The vertices' materials as WriteMaterialMesh computed them (for the renderer scenes,
// material_scene.h).
struct VertexMaterials {
  ScanMesh mesh;              // world frame (metres), with the mesh file's normals rotated where it has them
  std::vector<int> bases;     // the groups of the weights' columns
  Eigen::MatrixXd weights;    // vertices x bases, each row normalised to sum 1 (zero: no weights)
  std::vector<double> scale;  // per vertex, its cell's weights' sum before normalising (0: no weights)
  std::vector<int> label;     // the group of the largest weight, -1 none
  std::vector<uint8_t> fits;  // 1: its cell fits its combination
  std::vector<VertexWeightsFrom> from;
};

// Writes `path` (binary PLY, atomically): the session's mesh in the world frame (metres, the frame of
// the cameras), faces as the mesh file has them, its normals (rotated) where it has them, and per
// vertex: `label` (the group of the largest
// weight, -1 none), one float `weight_group_K` per basis K of `bases` (normalised to sum 1; 0 none),
// `residual` (the cell's relative RMS, -1 none), uchar `fits` (1: the cell fits its combination),
// uchar `weights_from` (VertexWeightsFrom), float `weight_sum` (the weights' sum before normalising:
// the vertex's brightness against the groups; 0 none), and red, green, blue (the bases' colours mixed by weight;
// magenta where the cell fits no combination, grey where none). `origin` and `cell_m` are the cells'
// grid. Fills `vertices` when given and written. Throws Error naming the mesh file when it cannot be
// read.
MaterialMeshResult WriteMaterialMesh(const Session& session, const MaterialWeightsResult& weights,
                                     const std::vector<int>& bases, const Eigen::Vector3d& origin, double cell_m,
                                     const std::string& path, VertexMaterials* vertices = nullptr);

}  // namespace ibrdf
