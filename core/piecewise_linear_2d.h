// A bilinearly interpolated 2D density on [0, 1]^2 with its sample warp (inversion method: a marginal
// distribution over rows, then a conditional over columns), optionally conditioned on up to three
// parameters between whose tabulated values it is interpolated linearly. This is the "Marginal2D"
// warp of Dupuy and Jakob 2018 through which every reader of the RGL ".bsdf" files (rgl-epfl's
// brdf-loader, Mitsuba 3's measured plugin, pbrt-v4's PiecewiseLinear2D) evaluates the tables; it is
// re-implemented here from brdf-loader's powitacq_rgb.inl in single precision, as the readers compute,
// so that core/rgl_bsdf.h evaluates a file as they do.
//
// Data layout: param_0 x param_1 x ... x size_y x size_x floats, the last index contiguous; x is the
// first coordinate of a position.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace ibrdf {

class PiecewiseLinear2D {
 public:
  PiecewiseLinear2D() = default;
  // `data` holds product(param sizes) * size_x * size_y values (size_x, size_y >= 2);
  // `param_values[d]` the (increasing) values at which parameter d is tabulated. With `normalize`
  // each slice is scaled to integrate to 1 over [0, 1]^2 (a density); `build_cdf` (implies normalize)
  // also builds the marginal and conditional CDFs that Sample and Invert need. Without either, Eval
  // returns the interpolated raw values.
  PiecewiseLinear2D(uint32_t size_x, uint32_t size_y, const float* data,
                    std::vector<std::vector<float>> param_values = {}, bool normalize = true, bool build_cdf = true);

  // Maps a uniform point of [0, 1]^2 to the distribution (given the parameters); returns the point and
  // its density.
  std::pair<Eigen::Vector2f, float> Sample(Eigen::Vector2f sample, const float* param = nullptr) const;
  // The inverse of Sample: a point of the distribution's domain to the uniform point, and its density.
  std::pair<Eigen::Vector2f, float> Invert(Eigen::Vector2f sample, const float* param = nullptr) const;
  // The (normalized, or raw) value at `pos`, bilinear in the position and linear in the parameters.
  float Eval(Eigen::Vector2f pos, const float* param = nullptr) const;

  uint32_t size_x() const { return size_x_; }
  uint32_t size_y() const { return size_y_; }

 private:
  // Interpolation weights (2 per parameter) and the slice offset of the parameters' lower nodes.
  uint32_t ParamWeights(const float* param, float* weights) const;
  // The value at flat index i0 of the first slice, interpolated over the parameters `dim` .. 1.
  float Lookup(const float* data, uint32_t i0, uint32_t slice_size, const float* weights, size_t dim) const;

  uint32_t size_x_ = 0, size_y_ = 0;
  float patch_x_ = 0.0f, patch_y_ = 0.0f;          // size of a bilinear patch in [0, 1]^2
  float inv_patch_x_ = 0.0f, inv_patch_y_ = 0.0f;  // patches per unit
  std::vector<uint32_t> param_size_, param_stride_;
  std::vector<std::vector<float>> param_values_;
  std::vector<float> data_, marginal_cdf_, conditional_cdf_;
};

}  // namespace ibrdf
