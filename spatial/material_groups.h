// Each group of the uniformity check's cells measured as a material of its own: the second step of
// Lensch et al. 2003's spatially varying BRDF (cluster the surface, then reconstruct one basis BRDF per
// cluster from its samples). Every sample is traced again onto the session's surface
// (surface_points.h). A sample away from the specular peak is given the group whose off-peak value
// (uniformity.json's centres, material_clusters.h) is nearest its own; every sample then takes the
// group most of its nearest such samples carry, of any photo (a sample on the peak cannot tell by its
// value; a cell on a sharp boundary holds two materials), and each group's samples go through the one
// reconstruction every object gets
// (reconstruct/reconstruction_stage.h: table, fits, exports). With a synthetic session's truth the
// groups are scored: each sample's true material at its surface point (synth/material_map.h) against
// its group, outside a margin about the truth's boundaries and blends, and each group's reconstruction
// against the material most of its samples carry.
// A single group is not reconstructed again: the object's own reconstruction is that group's. A group
// the check found to be a blend of two others (material_clusters.h) is counted, not reconstructed: its
// points are mixes. Then every cell of the surface, blends and boundaries included, is expressed as a
// non-negative combination of the reconstructed materials (material_weights.h, Lensch's projection),
// with its residual and whether any combination fits it. Two verdicts (core/verdict.h) judge the
// result: "materials.measured" (every group that is a material was reconstructed) and
// "materials.cells" (the cells no combination fits).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/session.h"
#include "core/verdict.h"
#include "reconstruct/reconstruction_stage.h"
#include "spatial/material_mesh.h"
#include "spatial/material_render.h"
#include "spatial/material_scene.h"
#include "spatial/material_weights.h"

namespace ibrdf {

class MaterialMap;  // synth/material_map.h

struct MaterialGroupsOptions {
  // Each group's reconstruction (truth_file and name are set per group; overwrite is not used).
  ReconstructOptions reconstruct;
  // The labels are scored on samples at least this far from a boundary or blend of the truth's map
  // (the 2 mm of docs/spatial.md's bound).
  double boundary_margin_m = 0.002;
  // A group with fewer samples is not reconstructed (its samples are counted, its folder not written).
  uint64_t min_group_samples = 1000;
  // Each sample takes the group most of its nearest off-peak samples carry (within a cell's edge;
  // else its cell's group).
  int neighbours = 16;
  // An off-peak sample whose value is beyond this of every group's centre (1.25x, the clustering's
  // separation) is a mix; a sample most of whose neighbours are mixes, or with a neighbour of another
  // group, lies on a boundary or in a blend and goes into no basis (counted as mixed).
  double purity = 0.25;
  size_t chunk_rows = 1 << 20;  // samples read (and traced in parallel) per chunk
  // Each cell's weights over the reconstructed materials, and the verdict on the cells none fits.
  MaterialWeightsOptions weights;
  PbrtSceneOptions pbrt;
  // The photo predicted from the model (and rendered in the pbrt-v4 scene): -1, the one with the most
  // samples. With hold_out its samples take no part in the grouping, reconstructions and weights.
  int photo = -1;
  bool hold_out = false;

  bool Check(std::string* why) const;
};

struct MaterialGroup {
  uint64_t samples = 0;
  // A blend of these two groups (a smooth boundary's cells: not reconstructed), or {-1, -1}.
  std::array<int, 2> blend_of = {-1, -1};
  bool reconstructed = false;
  std::string folder;  // "group-0", relative to the output folder ("" when not reconstructed)
  std::string material_name;  // its exported materials' name (NAME-group-K)
  ReconstructResult reconstruction;
  int truth_material = -1;  // with a map truth: the material most of its scored samples carry
  std::string truth_name;   // its name in the map ("" without one)
};

struct MaterialGroupsResult {
  uint64_t samples = 0;           // rows of the file
  uint64_t not_located = 0;       // not found again on the surface (SurfaceLocator outcomes other than found)
  uint64_t ungrouped = 0;         // in a cell without a group (not scored in all three channels) or no cell
  uint64_t off_peak_samples = 0;  // the samples whose own value chose their group (the neighbours voted)
  uint64_t mixed = 0;             // on a boundary or in a blend: in no group's reconstruction
  uint64_t mixed_scored = 0;      // of them, away from the truth's boundaries (counted as wrong labels)
  std::vector<MaterialGroup> groups;
  // With a map truth: samples outside the margin, per group and true material (groups x materials),
  // and the fraction whose group is a material and its majority material theirs.
  std::vector<std::string> truth_materials;
  std::vector<std::vector<uint64_t>> confusion;
  uint64_t scored = 0;
  double labels_right = 0.0;
  std::string truth_kind;  // "map", "material" (one material scores every group) or "" (no truth)
  // The cells' weights over the reconstructed groups (`bases`, by group index; none with one group).
  std::vector<int> bases;
  MaterialWeightsResult weights;
  // Each basis is its group's table where that has data, else its chosen fit: the evaluations (samples x
  // bases) and those the fit served (a fit outside its group's data, stated).
  uint64_t basis_evaluations = 0, basis_fit_evaluations = 0;
  // The mesh with each vertex's weights (out_dir/materials.ply; a mesh sample with more than one group).
  MaterialMeshResult mesh;
  // A pbrt-v4 scene of the photo with the most samples, rendered from the measured model.
  PbrtSceneResult pbrt;
  // That photo's samples predicted from the model, beside the one BRDF and the truth.
  PhotoPrediction prediction;
  uint64_t held_out = 0;  // located samples of a held-out photo (in no group)
  // With a map truth: per fitted cell, half the L1 distance between its weights (normalised to sum 1,
  // each basis counted as its group's majority material) and the truth's mean weights over its samples;
  // the median and 95th percentile over all such cells and over the cells the truth mixes (no material
  // over 0.95).
  uint64_t weights_scored_cells = 0, weights_mixed_cells = 0;
  double weights_error_median = 0.0, weights_error_p95 = 0.0, weights_mixed_error_median = 0.0;
  std::vector<Verdict> verdicts;  // "materials.measured", "materials.cells" (with more than one group)
  double seconds = 0.0;

  // "3 groups: 41 / 33 / 26 % of 1.2 M samples, reconstructed in 12.3 s; labels right on 97.1 % ..."
  std::string BriefReport() const;
  nlohmann::json ToJson() const;
};

// Splits the samples at `samples_path` by the groups of `uniformity` (uniformity.json as written by
// `ibrdf uniformity`, read from `uniformity_path`, named in errors) and reconstructs each group into
// `out_dir`/group-K (out_dir must exist), then projects every cell onto the reconstructed groups and
// states the verdicts (not enforced here: the caller writes the evidence first). `truth_map` scores the labels and each group against its
// majority material (nullptr: none); `truth_file`, a single-material truth, scores every group
// against it ("" for none; not with a map). Throws Error naming the file for a uniformity.json without
// its grid or cells, or unreadable samples.
MaterialGroupsResult MeasureMaterialGroups(const Session& session, const std::string& samples_path,
                                           const nlohmann::json& uniformity, const std::string& uniformity_path,
                                           const MaterialMap* truth_map, const std::string& truth_file,
                                           const MaterialGroupsOptions& options, const std::string& out_dir);

}  // namespace ibrdf
