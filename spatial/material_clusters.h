// How many materials do the uniformity check's cells show, and which cell is which? The first step
// of Lensch et al. 2003's spatially varying BRDF: group the surface into a few basis materials. Here
// the cells of the uniformity check (spatial/uniformity.h) are grouped by their ratio to the object's
// one BRDF, per channel and in logarithms. k-means (k-means++ seeding from a fixed seed, several
// starts, the lowest within-cluster sum kept) for k = 1 ... max_materials; the number of groups is the
// largest k whose clusters are all told apart: every pair of centres more than `separation` apart in
// some channel (the uniformity check's own 1.25x), and every cluster at least `min_share` of the
// cells. One group always qualifies, so a uniform sample gives one.
// A group is a material where the materials differ in albedo more than in lobe (Lambertian stripes:
// every cell labelled right); a glossy material's ratio to the average changes with the directions
// each cell saw, so it may share a group or split (docs/spatial.md gives the figures, and those of
// Lensch's per-group refit, which was tried and did not help).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace ibrdf {

struct MaterialClusterOptions {
  int max_materials = 4;
  double separation = 0.25;  // centres differ by more than 1.25x (or under 1 / 1.25x) in some channel
  double min_share = 0.05;   // of the clustered cells
  int starts = 8;            // k-means++ starts per k

  bool Check(std::string* why) const;
};

struct MaterialClusters {
  int count = 0;                   // the groups found (0: no cell had all three channels scored)
  std::vector<int> cell_label;     // per cell: its cluster, -1 for cells not clustered
  std::vector<Eigen::Vector3d> ratio;  // per cluster, its centre as a ratio to the object's (per channel)
  std::vector<double> share;       // per cluster, its fraction of the clustered cells
  size_t clustered = 0;            // cells with all three channels scored
  // Per k tried: why it was or was not taken ("2: centres 1.31x apart, smallest 18 % of cells").
  std::vector<std::string> tried;

  // "the cells' ratios form 3 groups (cells 41 / 33 / 26 %; ratios ...)": groups, not yet materials
  // (a glossy material's ratio to the average changes with the directions a cell saw).
  std::string BriefReport() const;
  nlohmann::json ToJson() const;
};

// `cell_ratio`: per cell and channel its ratio to the object's (NaN where not scored); cells scored in
// all three channels are clustered.
MaterialClusters ClusterMaterials(const std::vector<Eigen::Vector3d>& cell_ratio, const MaterialClusterOptions& options);

}  // namespace ibrdf
