// Each surface cell as a combination of the measured materials: the projection step of Lensch et al.
// 2003 (section 7, "projection": a point's samples expressed as a non-negative combination of the basis
// BRDFs, f(x; wi, wo) = sum_g w_g(x) f_g(wi, wo)). The bases are the materials the groups were
// reconstructed as (material_groups.h); the points are the uniformity check's cells (a few mm across),
// since one surface point holds a sample per photo that sees it while a cell holds hundreds. Per cell:
// the weights, the residual of its samples against their combination, and whether it fits: a cell whose
// median ratio to its combination is beyond the uniformity check's bound in some channel (1.25x and
// 4 of its own standard errors) is a material no basis spans, or a wrong geometry there.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "core/brdf_model.h"
#include "core/sample_file.h"

namespace ibrdf {

// The most bases a projection takes (every subset of them is solved: 2^8 - 1 per cell).
constexpr int kMaxBases = 8;

struct MaterialWeightsOptions {
  // A cell needs this many samples usable against every basis in some channel to be fitted (the
  // uniformity check's min_cell_samples).
  int min_cell_samples = 24;
  // A cell does not fit when a channel's median ratio to its combination is beyond this factor (1.25x or
  // 1 / 1.25x) and beyond noise_sigmas of that median's standard error.
  double deviation = 0.25;
  double noise_sigmas = 4.0;
  // The verdict "materials.cells" on the fraction of fitted cells that do not fit (the uniformity
  // check's bounds: docs/spatial.md).
  double warn_fraction = 0.05;
  double fail_fraction = 0.15;

  bool Check(std::string* why) const;
};

// One sample where it was found on the surface: its cell (UniformityCellKey) and point.
struct LocatedSample {
  BrdfSample sample;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  int8_t group = -1;  // the group it was given (material_groups.cc's codes; not used here)
  uint64_t key = 0;
};

struct CellWeights {
  uint64_t key = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the mean point of its samples
  uint32_t samples = 0;                               // located in the cell
  uint32_t usable = 0;                                // sample channels used in the fit
  bool fitted = false;                                // enough usable samples
  Eigen::VectorXd weights;                            // per basis, non-negative (empty: not fitted)
  // Per channel the median ratio of its samples to their combination and that median's standard error
  // (NaN where the channel had too few samples).
  Eigen::Vector3d ratio = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d noise = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double rel_rms = std::numeric_limits<double>::quiet_NaN();  // of (sample - combination) / the bases' mean
  bool fits = false;                                          // fitted, and every channel within the bound
  int dominant = -1;                                          // the basis with the largest weight
};

struct MaterialWeightsResult {
  size_t bases = 0;
  std::vector<CellWeights> cells;  // by key, ascending
  uint64_t cells_fitted = 0;
  uint64_t cells_not_fitting = 0;
  double not_fitting_fraction = 0.0;     // of the fitted cells
  double median_rel_rms = 0.0;           // over the fitted cells
  double seconds = 0.0;

  // "weights: 2841 cells over 2 bases; 1.2 % do not fit (beyond 1.25x and 4 sigma); median residual 4.1 %"
  std::string BriefReport(const MaterialWeightsOptions& options) const;
};

// Sorts `samples` by cell and fits each cell's samples as a non-negative combination of `bases` (each
// evaluated at the sample's local wi, wo; a channel where a basis has no data, a negative value, is not
// used): the weights minimise the squared residuals relative to the bases' mean at each sample's
// directions (so that a cell's bright highlight and dim off-peak samples count alike), solved
// exactly, with the weights bounded below by 0. Throws Error for no basis, over kMaxBases, or bad
// options.
MaterialWeightsResult ProjectOntoBases(std::vector<LocatedSample>* samples, const std::vector<const BrdfModel*>& bases,
                                       const MaterialWeightsOptions& options);

// The fitted cells of `weights` by their key (UniformityCellKey), as indices into its `cells`.
std::unordered_map<uint64_t, size_t> FittedCellsByKey(const MaterialWeightsResult& weights);

}  // namespace ibrdf
