#include "core/piecewise_linear_2d.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ibrdf {
namespace {

constexpr float kOneMinusEpsilon = 0.999999940395355225f;

// The index i in [0, size - 2] with pred(i) true and pred(i + 1) false (clamped at either end), by
// bisection: the interval of an increasing sequence holding a value.
template <typename Predicate>
uint32_t FindInterval(uint32_t size, const Predicate& pred) {
  int64_t remaining = int64_t(size) - 2, first = 1;
  while (remaining > 0) {
    const int64_t half = remaining >> 1, middle = first + half;
    if (pred(uint32_t(middle))) {
      first = middle + 1;
      remaining -= half + 1;
    } else {
      remaining = half;
    }
  }
  return uint32_t(std::clamp<int64_t>(first - 1, 0, int64_t(size) - 2));
}

}  // namespace

PiecewiseLinear2D::PiecewiseLinear2D(uint32_t size_x, uint32_t size_y, const float* data,
                                     std::vector<std::vector<float>> param_values, bool normalize, bool build_cdf)
    : size_x_(size_x),
      size_y_(size_y),
      patch_x_(1.0f / float(size_x - 1)),
      patch_y_(1.0f / float(size_y - 1)),
      inv_patch_x_(float(size_x - 1)),
      inv_patch_y_(float(size_y - 1)),
      param_values_(std::move(param_values)) {
  IBRDF_CHECK(size_x >= 2 && size_y >= 2) << size_x << " x " << size_y;
  IBRDF_CHECK(normalize || !build_cdf);
  const size_t dims = param_values_.size();
  IBRDF_CHECK(dims <= 3);
  param_size_.resize(dims);
  param_stride_.resize(dims);
  uint32_t slices = 1;
  for (int d = int(dims) - 1; d >= 0; --d) {
    IBRDF_CHECK(!param_values_[d].empty());
    param_size_[d] = uint32_t(param_values_[d].size());
    param_stride_[d] = param_size_[d] > 1 ? slices : 0;
    slices *= param_size_[d];
  }
  const uint32_t n = size_x * size_y;
  data_.resize(size_t(slices) * n);
  if (build_cdf) {
    marginal_cdf_.resize(size_t(slices) * size_y);
    conditional_cdf_.resize(size_t(slices) * n);
    for (uint32_t slice = 0; slice < slices; ++slice) {
      const float* in = data + size_t(slice) * n;
      float* conditional = conditional_cdf_.data() + size_t(slice) * n;
      float* marginal = marginal_cdf_.data() + size_t(slice) * size_y;
      float* out = data_.data() + size_t(slice) * n;
      // Per row, the integral of the linear interpolant from the row's start (trapezoids).
      for (uint32_t y = 0; y < size_y; ++y) {
        double sum = 0.0;
        size_t i = size_t(y) * size_x;
        conditional[i] = 0.0f;
        for (uint32_t x = 0; x + 1 < size_x; ++x, ++i) {
          sum += 0.5 * (double(in[i]) + double(in[i + 1]));
          conditional[i + 1] = float(sum);
        }
      }
      // Over rows, the integral of the rows' totals.
      marginal[0] = 0.0f;
      double sum = 0.0;
      for (uint32_t y = 0; y + 1 < size_y; ++y) {
        sum +=
            0.5 * (double(conditional[size_t(y + 1) * size_x - 1]) + double(conditional[size_t(y + 2) * size_x - 1]));
        marginal[y + 1] = float(sum);
      }
      const float normalization = 1.0f / marginal[size_y - 1];
      for (uint32_t i = 0; i < n; ++i) conditional[i] *= normalization;
      for (uint32_t i = 0; i < size_y; ++i) marginal[i] *= normalization;
      for (uint32_t i = 0; i < n; ++i) out[i] = in[i] * normalization;
    }
  } else {
    for (uint32_t slice = 0; slice < slices; ++slice) {
      const float* in = data + size_t(slice) * n;
      float* out = data_.data() + size_t(slice) * n;
      float normalization = 1.0f / (inv_patch_x_ * inv_patch_y_);
      if (normalize) {
        double sum = 0.0;
        for (uint32_t y = 0; y + 1 < size_y; ++y) {
          size_t i = size_t(y) * size_x;
          for (uint32_t x = 0; x + 1 < size_x; ++x, ++i) {
            sum += double(0.25f * (in[i] + in[i + 1] + in[i + size_x] + in[i + 1 + size_x]));
          }
        }
        normalization = float(1.0 / sum);
      }
      for (uint32_t k = 0; k < n; ++k) out[k] = in[k] * normalization;
    }
  }
}

uint32_t PiecewiseLinear2D::ParamWeights(const float* param, float* weights) const {
  uint32_t slice_offset = 0;
  for (size_t d = 0; d < param_size_.size(); ++d) {
    if (param_size_[d] == 1) {
      weights[2 * d] = 1.0f;
      weights[2 * d + 1] = 0.0f;
      continue;
    }
    const std::vector<float>& values = param_values_[d];
    const uint32_t index = FindInterval(param_size_[d], [&](uint32_t i) { return values[i] <= param[d]; });
    const float p0 = values[index], p1 = values[index + 1];
    weights[2 * d + 1] = std::clamp((param[d] - p0) / (p1 - p0), 0.0f, 1.0f);
    weights[2 * d] = 1.0f - weights[2 * d + 1];
    slice_offset += param_stride_[d] * index;
  }
  return slice_offset;
}

float PiecewiseLinear2D::Lookup(const float* data, uint32_t i0, uint32_t slice_size, const float* weights,
                                size_t dim) const {
  if (dim == 0) return data[i0];
  const uint32_t i1 = i0 + param_stride_[dim - 1] * slice_size;
  const float v0 = Lookup(data, i0, slice_size, weights, dim - 1);
  const float v1 = Lookup(data, i1, slice_size, weights, dim - 1);
  return std::fma(v0, weights[2 * dim - 2], v1 * weights[2 * dim - 1]);
}

std::pair<Eigen::Vector2f, float> PiecewiseLinear2D::Sample(Eigen::Vector2f sample, const float* param) const {
  IBRDF_CHECK(!marginal_cdf_.empty()) << "Sample without CDFs";
  sample = sample.cwiseMax(1.0f - kOneMinusEpsilon).cwiseMin(kOneMinusEpsilon);
  float weights[6];
  const uint32_t slice_offset = ParamWeights(param, weights);
  const size_t dims = param_size_.size();
  const uint32_t slice_size = size_x_ * size_y_;

  // The row from the marginal CDF.
  uint32_t offset = slice_offset * size_y_;
  auto marginal = [&](uint32_t i) { return Lookup(marginal_cdf_.data(), offset + i, size_y_, weights, dims); };
  const uint32_t row = FindInterval(size_y_, [&](uint32_t i) { return marginal(i) < sample.y(); });
  sample.y() -= marginal(row);

  offset = row * size_x_ + slice_offset * slice_size;
  const float r0 = Lookup(conditional_cdf_.data(), offset + size_x_ - 1, slice_size, weights, dims);
  const float r1 = Lookup(conditional_cdf_.data(), offset + 2 * size_x_ - 1, slice_size, weights, dims);
  bool is_const = std::abs(r0 - r1) < 1e-4f * (r0 + r1);
  sample.y() = is_const ? 2.0f * sample.y() : r0 - std::sqrt(r0 * r0 - 2.0f * sample.y() * (r0 - r1));
  sample.y() /= is_const ? r0 + r1 : r0 - r1;

  // The column from the conditional CDF, interpolated between the row's two edges.
  sample.x() *= (1.0f - sample.y()) * r0 + sample.y() * r1;
  auto conditional = [&](uint32_t i) {
    const float v0 = Lookup(conditional_cdf_.data(), offset + i, slice_size, weights, dims);
    const float v1 = Lookup(conditional_cdf_.data() + size_x_, offset + i, slice_size, weights, dims);
    return (1.0f - sample.y()) * v0 + sample.y() * v1;
  };
  const uint32_t col = FindInterval(size_x_, [&](uint32_t i) { return conditional(i) < sample.x(); });
  sample.x() -= conditional(col);
  offset += col;

  const float v00 = Lookup(data_.data(), offset, slice_size, weights, dims);
  const float v10 = Lookup(data_.data() + 1, offset, slice_size, weights, dims);
  const float v01 = Lookup(data_.data() + size_x_, offset, slice_size, weights, dims);
  const float v11 = Lookup(data_.data() + size_x_ + 1, offset, slice_size, weights, dims);
  const float c0 = std::fma(1.0f - sample.y(), v00, sample.y() * v01);
  const float c1 = std::fma(1.0f - sample.y(), v10, sample.y() * v11);
  is_const = std::abs(c0 - c1) < 1e-4f * (c0 + c1);
  sample.x() = is_const ? 2.0f * sample.x() : c0 - std::sqrt(c0 * c0 - 2.0f * sample.x() * (c0 - c1));
  sample.x() /= is_const ? c0 + c1 : c0 - c1;

  const Eigen::Vector2f p((float(col) + sample.x()) * patch_x_, (float(row) + sample.y()) * patch_y_);
  return {p, ((1.0f - sample.x()) * c0 + sample.x() * c1) * inv_patch_x_ * inv_patch_y_};
}

std::pair<Eigen::Vector2f, float> PiecewiseLinear2D::Invert(Eigen::Vector2f sample, const float* param) const {
  IBRDF_CHECK(!marginal_cdf_.empty()) << "Invert without CDFs";
  float weights[6];
  const uint32_t slice_offset = ParamWeights(param, weights);
  const size_t dims = param_size_.size();
  const uint32_t slice_size = size_x_ * size_y_;

  // The bilinear patch holding the point.
  sample.x() *= inv_patch_x_;
  sample.y() *= inv_patch_y_;
  const uint32_t px = std::min(uint32_t(std::max(sample.x(), 0.0f)), size_x_ - 2);
  const uint32_t py = std::min(uint32_t(std::max(sample.y(), 0.0f)), size_y_ - 2);
  sample.x() -= float(int32_t(px));
  sample.y() -= float(int32_t(py));
  uint32_t offset = px + py * size_x_ + slice_offset * slice_size;

  const float v00 = Lookup(data_.data(), offset, slice_size, weights, dims);
  const float v10 = Lookup(data_.data() + 1, offset, slice_size, weights, dims);
  const float v01 = Lookup(data_.data() + size_x_, offset, slice_size, weights, dims);
  const float v11 = Lookup(data_.data() + size_x_ + 1, offset, slice_size, weights, dims);
  const float w1x = sample.x(), w1y = sample.y(), w0x = 1.0f - w1x, w0y = 1.0f - w1y;
  const float c0 = std::fma(w0y, v00, w1y * v01), c1 = std::fma(w0y, v10, w1y * v11);
  const float pdf = std::fma(w0x, c0, w1x * c1);

  // x: the conditional CDF within the row pair.
  sample.x() *= c0 + 0.5f * sample.x() * (c1 - c0);
  const float v0 = Lookup(conditional_cdf_.data(), offset, slice_size, weights, dims);
  const float v1 = Lookup(conditional_cdf_.data() + size_x_, offset, slice_size, weights, dims);
  sample.x() += (1.0f - sample.y()) * v0 + sample.y() * v1;
  offset = py * size_x_ + slice_offset * slice_size;
  const float r0 = Lookup(conditional_cdf_.data(), offset + size_x_ - 1, slice_size, weights, dims);
  const float r1 = Lookup(conditional_cdf_.data(), offset + 2 * size_x_ - 1, slice_size, weights, dims);
  sample.x() /= (1.0f - sample.y()) * r0 + sample.y() * r1;

  // y: the marginal CDF.
  sample.y() *= r0 + 0.5f * sample.y() * (r1 - r0);
  offset = py + slice_offset * size_y_;
  sample.y() += Lookup(marginal_cdf_.data(), offset, size_y_, weights, dims);
  return {sample, pdf * inv_patch_x_ * inv_patch_y_};
}

float PiecewiseLinear2D::Eval(Eigen::Vector2f pos, const float* param) const {
  float weights[6];
  const uint32_t slice_offset = ParamWeights(param, weights);
  const size_t dims = param_size_.size();
  pos.x() *= inv_patch_x_;
  pos.y() *= inv_patch_y_;
  const uint32_t ox = std::min(uint32_t(std::max(pos.x(), 0.0f)), size_x_ - 2);
  const uint32_t oy = std::min(uint32_t(std::max(pos.y(), 0.0f)), size_y_ - 2);
  const float w1x = pos.x() - float(int32_t(ox)), w1y = pos.y() - float(int32_t(oy));
  const float w0x = 1.0f - w1x, w0y = 1.0f - w1y;
  const uint32_t slice_size = size_x_ * size_y_;
  const uint32_t index = ox + oy * size_x_ + slice_offset * slice_size;
  const float v00 = Lookup(data_.data(), index, slice_size, weights, dims);
  const float v10 = Lookup(data_.data() + 1, index, slice_size, weights, dims);
  const float v01 = Lookup(data_.data() + size_x_, index, slice_size, weights, dims);
  const float v11 = Lookup(data_.data() + size_x_ + 1, index, slice_size, weights, dims);
  return std::fma(w0y, std::fma(w0x, v00, w1x * v10), w1y * std::fma(w0x, v01, w1x * v11)) * inv_patch_x_ *
         inv_patch_y_;
}

}  // namespace ibrdf
