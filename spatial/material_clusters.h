// How many materials do the uniformity check's cells show, and which cell is which? The first step
// of Lensch et al. 2003's spatially varying BRDF: group the surface into a few basis materials. Here
// the cells of the uniformity check (spatial/uniformity.h) are grouped by their samples' median BRDF
// value away from the specular peak, relative to the median cell's, per channel and in logarithms
// (there a material's value hardly depends on the directions each cell saw; its ratio to the one
// reconstructed BRDF does, since that is another mix of the materials at each direction). k-means
// (OpenCV's, k-means++ seeding from a fixed seed, several starts, the most compact kept) for k = 1
// ... max_materials; the number of groups is the largest k whose clusters are all told apart: every
// pair of centres more than `separation` apart in some channel (1.6x), and every cluster at least
// `min_share` of the cells. One group always qualifies, so a uniform sample gives one. A group whose
// centre is within `blend_tolerance` of a mix of two others' is a blend of them (the cells of a smooth
// boundary), not a material (docs/spatial.md gives the figures).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace ibrdf {

struct MaterialClusterOptions {
  int max_materials = 4;
  // Centres differ by more than 1.6x (or under 1 / 1.6x) in some channel: a uniform object's cells
  // differ by up to 1.41x off the peak where a broad lobe adds at some directions and not others
  // (docs/spatial.md), the seed paper's materials on the squash by 2.3x and more.
  double separation = 0.6;
  // A group within this of a mix of two others' centres (1.25x) is their blend.
  double blend_tolerance = 0.25;
  double min_share = 0.05;   // of the clustered cells
  int starts = 8;            // k-means++ attempts per k

  bool Check(std::string* why) const;
};

struct MaterialClusters {
  int count = 0;                   // the groups found (0: no cell had all three channels scored)
  std::vector<int> cell_label;     // per cell: its cluster, -1 for cells not clustered
  std::vector<Eigen::Vector3d> ratio;  // per cluster, its centre as a ratio to the object's (per channel)
  std::vector<double> share;       // per cluster, its fraction of the clustered cells
  size_t clustered = 0;            // cells with all three channels scored
  // Per cluster: the two clusters it is a blend of (its centre within the separation of a mix of
  // theirs: a smooth boundary's cells), or {-1, -1} for a material.
  std::vector<std::array<int, 2>> blend_of;
  int materials = 0;  // clusters that are not blends
  // Per k tried: why it was or was not taken ("2: centres 1.31x apart, smallest 18 % of cells").
  std::vector<std::string> tried;

  bool IsBlend(int group) const;

  // "the cells form 4 groups (cells 46 / 20 / 11 / 23 %; off-peak values ...): 3 materials, group 2 a
  // blend of 1 and 3".
  std::string BriefReport() const;
  nlohmann::json ToJson() const;
};

// `cell_ratio`: per cell and channel its ratio to the object's (NaN where not scored); cells scored in
// all three channels are clustered.
MaterialClusters ClusterMaterials(const std::vector<Eigen::Vector3d>& cell_ratio, const MaterialClusterOptions& options);

}  // namespace ibrdf
