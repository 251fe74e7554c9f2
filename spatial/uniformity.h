// Is the sample one material? The derenderer and the reconstruction take every pixel of the object as
// a sample of one BRDF; a striped squash or a glazed pot with bare clay breaks that silently: the one
// BRDF averages its materials. This check divides the surface into cells (a voxel grid over the
// world points the samples came from, surface_points.h) and compares each cell's samples with the
// reconstructed BRDF at the same directions: per cell and channel the median ratio sample / BRDF.
// On a uniform object every cell's ratio is the object's, within its noise (the spread of the cell's
// own ratios over the square root of their number) and the reconstruction's smoothing; a cell of
// another material differs by its albedo or lobe. A cell deviates when, in a channel, its ratio is off
// the object's (the median over cells) by more than `deviation` and by more than `noise_sigmas` of its
// noise. The verdict (core/verdict.h) is on the fraction of cells that deviate; its map is a photo
// with each sample pixel coloured by its cell's ratio.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/session.h"
#include "core/verdict.h"
#include "spatial/material_clusters.h"

namespace ibrdf {

struct UniformityOptions {
  // The cells' edge, metres; 0: the sample's bounding radius / 16 (about 2.8 mm on a 9 cm squash,
  // 16 cells across a stripe of a twelfth of its girth), or 2 or 4 times that where too few samples
  // fill those cells (the finest at which half the usable samples lie in cells of min_cell_samples).
  double cell_m = 0.0;
  // Cells with fewer usable samples in a channel are not scored in it.
  int min_cell_samples = 24;
  // A channel's ratio deviates by more than this factor (1.25: above 1.25x or below 1 / 1.25x the
  // object's) and by more than noise_sigmas of the cell's noise.
  double deviation = 0.25;
  double noise_sigmas = 4.0;
  // The verdict "uniformity.cells" on the fraction of scored cells that deviate (docs/spatial.md
  // gives the figures these were chosen from).
  double warn_fraction = 0.05;
  double fail_fraction = 0.15;
  // Samples read per chunk of the file (memory stays bounded by the per-sample ratios kept, 16 bytes
  // each).
  size_t chunk_rows = 1 << 20;
  // How the cells are grouped into materials (reported, with each cell's label; the verdict is the
  // deviating cells' alone).
  MaterialClusterOptions clusters;
  // The cells are grouped by the median BRDF value of their samples whose half vector is at least this
  // far from the normal (degrees; 0: all samples): away from a glossy material's specular peak.
  double cluster_min_theta_h_deg = 20.0;

  bool Check(std::string* why) const;
};

struct UniformityCell {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the mean world point of its samples
  uint32_t samples = 0;                               // samples located in the cell
  Eigen::Vector3d ratio = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  // NaN: not scored
  Eigen::Vector3d noise = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  // of the ratio
  // The median BRDF value of its samples away from the peaks (UniformityOptions::
  // cluster_min_theta_h_deg), which the groups are formed from; NaN where too few.
  Eigen::Vector3d off_peak_brdf = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool deviates = false;
  uint64_t key = 0;  // its grid coordinates (UniformityResult::grid_origin, cell_m), packed
};

struct UniformityResult {
  double cell_m = 0.0;
  Eigen::Vector3d grid_origin = Eigen::Vector3d::Zero();  // the cells' grid: corner of cell (0, 0, 0)
  uint64_t samples = 0;          // rows of the file
  uint64_t located = 0;          // samples whose surface point was found
  uint64_t no_pose = 0;          // SurfaceLocator outcomes other than found
  uint64_t missed = 0;
  uint64_t mismatched = 0;
  uint64_t no_reference = 0;     // located samples with no channel where both sample and BRDF are usable
  std::vector<UniformityCell> cells;
  Eigen::Vector3d object_ratio = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  uint64_t cells_scored = 0;     // cells with a ratio in at least one channel
  uint64_t cells_deviating = 0;
  double deviating_fraction = 0.0;  // cells_deviating / cells_scored
  // Per channel, the 90th over the 10th percentile of the scored cells' ratios (1 for one material).
  Eigen::Vector3d spread = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double max_ratio = 0.0, min_ratio = 0.0;  // over scored cells and channels, relative to the object's
  MaterialClusters materials;     // the cells grouped by their ratios (cells[i] has label materials.cell_label[i])
  double cluster_min_theta_h_deg = 0.0;  // the samples they were grouped by (UniformityOptions)
  // The median cell's off-peak BRDF value, per channel: the groups' centres are relative to it.
  Eigen::Vector3d object_off_peak_brdf = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::vector<Verdict> verdicts;  // "uniformity.cells", "uniformity.located"
  size_t map_photo = 0;           // the session photo the map draws on (the one with most scored samples)
  double seconds = 0.0;

  // "uniformity: 3 % of 2804 cells deviate (over 1.25x and 4 sigma); spread 1.08x ..."
  std::string BriefReport() const;
  // The summary (no per-cell list) and the verdicts, plus "cells" when `with_cells`.
  nlohmann::json ToJson(bool with_cells) const;
};

// The key of the cell that holds `point` in the grid of cells of edge `cell_m` from corner `origin`: its
// integer grid coordinates, 21 bits each (a million cells along each axis), as UniformityCell::key and
// uniformity.json's "key" hold them.
uint64_t UniformityCellKey(const Eigen::Vector3d& point, const Eigen::Vector3d& origin, double cell_m);

// The median of `values` (reordered) and that median's standard error from their own scatter: 1.4826
// MAD is a sigma, and the median of n values has sqrt(pi / 2) / sqrt(n) of it. `values` not empty.
void MedianAndStandardError(std::vector<float>* values, double* median, double* standard_error);

// Whether a cell's ratio deviates from `reference`: by more than the factor 1 + deviation either way and
// by more than noise_sigmas of its standard error `noise` (the uniformity check's test, and the
// materials stage's for a cell against its combination of the groups).
bool RatioDeviates(double ratio, double reference, double noise, double deviation, double noise_sigmas);

// Whether a deviation test's options are sane (false with `why`): deviation > 0, noise_sigmas >= 0, and
// 0 < warn_fraction <= fail_fraction <= 1 (the uniformity check's options and the materials stage's).
bool CheckDeviationBound(double deviation, double noise_sigmas, double warn_fraction, double fail_fraction,
                         std::string* why);

// Measures the session's samples (the file at `samples_path`) against `reference`, the BRDF
// reconstructed from them. Throws Error naming the file for unreadable samples, and naming the session
// when most samples cannot be located on its surface (not this session's samples).
UniformityResult MeasureUniformity(const Session& session, const std::string& samples_path, const BrdfModel& reference,
                                   const UniformityOptions& options);

// The map: photo `result.map_photo` in grey, its sample pixels coloured by their cell's ratio to the
// object's in the channel furthest from it (red above, blue below, white at 1; full colour at 2x or
// 1 / 2x; cells that do not deviate at half strength). Re-traces that photo's samples.
Image UniformityMap(const Session& session, const std::string& samples_path, const UniformityResult& result,
                    const UniformityOptions& options);

}  // namespace ibrdf
