#include "reconstruct/local_regression.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <random>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <Eigen/Cholesky>
#include <nanoflann.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/math.h"
#include "reconstruct/normal_accumulation.h"

namespace ibrdf {
namespace {

constexpr int kMaxCoefficients = 10;
constexpr int kCoefficients[3] = {1, 4, 10};

// One point of the regression (a bin of samples, or one sample without binning), packed into one cache
// line: the kd-tree's distance test and the normal equations read the same 64 bytes.
struct alignas(64) Point {
  float xyz[3];    // centroid, scaled canonical coordinates
  float value[3];  // mean value (log f in log space)
  float low[3];    // range of its samples' values
  float high[3];
  uint32_t count;  // samples
};

// The point cloud as nanoflann wants it.
struct Cloud {
  std::vector<Point> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t index, size_t dim) const { return points[index].xyz[dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, uint32_t>;

// One mirror image of the domain: signs applied to (u, v); w never changes sign.
struct Mirror {
  float su, sv;
};

// Accumulates the weighted normal equations of a degree-2 fit directly from the kd-tree's radius search.
// Degree 1 and 0 use leading blocks of the same matrices, because the basis is nested: 1, x, y, z, x^2,
// y^2, z^2, xy, xz, yz. A point is a bin of `count` samples at its centroid with their mean
// value: it adds count * w to the weights and count * w^2 to the squared weights, as that many samples
// at one place would. The search keeps each point's weights, basis row and mean value (`rows`, a
// per-thread buffer); Accumulate() then sums the upper triangle of the normal matrix and the right-hand
// sides row by row with the sums in registers (each element summed over the points in the order the
// search found them, as adding them point by point did: the same bits). The estimate's variance
// g' A2 g (A2 the normal matrix with squared weights) is not accumulated as a matrix: Variance(g) sums
// count * w^2 (basis . g)^2 over the rows, 11 multiply-adds a point instead of 55 (docs/decisions.md,
// "Reconstruct speed").
struct NormalEquations {
  const Point* cloud = nullptr;
  // Leave-one-out: the point holding the left-out sample, and that sample's position and value, which
  // are taken out of the point's statistics.
  int64_t exclude = -1;
  const float* exclude_xyz = nullptr;
  const float* exclude_value = nullptr;
  // Generalized cross-validation: the point holding the sample whose leverage is wanted; its weight times
  // basis, summed over mirror images, goes to self_basis.
  int64_t self = -1;
  double self_basis[kMaxCoefficients] = {};
  float query[3] = {0, 0, 0};
  Mirror mirror{1, 1};
  float radius = 1.0f;  // of the support in scaled units (the growth factor)
  float radius_squared = 1.0f;
  // Only count the samples with non-zero weight and sum their weights (sum_w, count, points), and stop
  // the search once count >= enough_count with a positive sum: whether a support suffices.
  bool count_only = false;
  uint32_t enough_count = 0;

  double a[kMaxCoefficients][kMaxCoefficients] = {};  // upper triangle (j >= i) only; by Accumulate()
  double b[kMaxCoefficients][3] = {};                 // by Accumulate()
  // Per point with non-zero weight: count * w^2, count * w, its basis row and its mean value (kRowSize
  // doubles a point).
  static constexpr int kSquaredWeight = kNormalSquaredWeight, kWeight = kNormalWeight, kBasis = kNormalBasis,
                       kMean = kNormalMean;
  static constexpr int kRowSize = kNormalRowSize;
  static_assert(kMaxCoefficients == kNormalCoefficients);
  std::vector<double>* rows = nullptr;
  size_t rows_used = 0;  // doubles of `rows` in use
  double sum_w = 0.0, sum_w2 = 0.0;
  float low[3] = {0, 0, 0}, high[3] = {0, 0, 0};                   // range of the neighbours' values
  uint32_t count = 0;                                              // samples with non-zero weight
  uint32_t points = 0;                                             // points (bins) with non-zero weight
  float nearest_squared = std::numeric_limits<float>::infinity();  // of the points with non-zero weight

  // nanoflann's result-set interface.
  float worstDist() const { return radius_squared; }
  size_t size() const { return points; }
  bool full() const { return true; }
  [[gnu::always_inline]] bool addPoint(float distance_squared, uint32_t index) {
    if (distance_squared >= radius_squared) return true;
    const Point& point = cloud[index];
    const float* p = point.xyz;
    const float* f = point.value;
    double n = point.count;
    float position[3] = {p[0], p[1], p[2]};
    float mean[3] = {f[0], f[1], f[2]};
    if (static_cast<int64_t>(index) == exclude) {
      if (n <= 1.0) return true;
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        position[k] = static_cast<float>((n * p[k] - exclude_xyz[k]) / (n - 1.0));
        mean[k] = static_cast<float>((n * f[k] - exclude_value[k]) / (n - 1.0));
        const double dk = double(position[k]) - query[k];
        d2 += dk * dk;
      }
      n -= 1.0;
      distance_squared = static_cast<float>(d2);
      if (distance_squared >= radius_squared) return true;
    }
    // Offsets in support radii; the divisions are skipped at the given radius (growth 1), where they
    // would divide by 1.
    double r = std::sqrt(double(distance_squared));
    float ox = mirror.su * (position[0] - query[0]), oy = mirror.sv * (position[1] - query[1]),
          oz = position[2] - query[2];
    if (radius != 1.0f) {
      r /= radius;
      ox /= radius;
      oy /= radius;
      oz /= radius;
    }
    const double t = 1.0 - r * r * r;
    const double w = t * t * t;
    if (!(w > 0.0)) return true;
    if (count_only) {
      sum_w += n * w;
      count += static_cast<uint32_t>(n);
      ++points;
      return !(count >= enough_count && sum_w > 0.0);  // false stops the search: the support suffices
    }
    const double dx = ox, dy = oy, dz = oz;
    const double basis[kMaxCoefficients] = {1.0, dx, dy, dz, dx * dx, dy * dy, dz * dz, dx * dy, dx * dz, dy * dz};
    for (int c = 0; c < 3; ++c) {
      low[c] = points == 0 ? point.low[c] : std::min(low[c], point.low[c]);
      high[c] = points == 0 ? point.high[c] : std::max(high[c], point.high[c]);
    }
    const double nw = n * w, nw2 = nw * w;
    if (rows_used + kRowSize + kNormalRowPadding > rows->size()) {
      rows->resize(std::max<size_t>(2 * rows->size(), 64 * kRowSize + kNormalRowPadding));
    }
    double* row = rows->data() + rows_used;
    rows_used += kRowSize;
    row[kSquaredWeight] = nw2;
    row[kWeight] = nw;
    std::copy(std::begin(basis), std::end(basis), row + kBasis);
    for (int c = 0; c < 3; ++c) row[kMean + c] = mean[c];
    if (static_cast<int64_t>(index) == self) {
      for (int i = 0; i < kMaxCoefficients; ++i) self_basis[i] += w * basis[i];
    }
    sum_w += nw;
    sum_w2 += nw2;
    nearest_squared = std::min(nearest_squared, distance_squared);
    count += static_cast<uint32_t>(n);
    ++points;
    return true;
  }
  // The normal equations (a, b) of the points the last full search found (reconstruct/normal_accumulation.h:
  // each element summed over the points in the order the search found them).
  void Accumulate() { AccumulateNormalEquations(rows->data(), rows_used / kRowSize, a, b); }
  // g' A2 g for the leading m coefficients g (A2: the normal matrix with squared weights).
  double Variance(const double* g, int m) const {
    double variance = 0.0;
    for (size_t p = 0; p < rows_used; p += kRowSize) {
      const double* row = rows->data() + p;
      double t = 0.0;
      for (int i = 0; i < m; ++i) t += row[kBasis + i] * g[i];
      variance += row[kSquaredWeight] * t * t;
    }
    return variance;
  }
  void Reset() {
    rows_used = 0;
    for (auto& row : a) std::fill(std::begin(row), std::end(row), 0.0);
    for (auto& row : b) std::fill(std::begin(row), std::end(row), 0.0);
    std::fill(std::begin(self_basis), std::end(self_basis), 0.0);
    sum_w = sum_w2 = 0.0;
    count = points = 0;
    nearest_squared = std::numeric_limits<float>::infinity();
  }
};


// The standard error per channel of a fit of `degree` with coefficients `coefficients` (fitting space;
// m x 3 for m = kCoefficients[degree]) and weights g = A^-1 e1 (the estimate is sum_p n_p w_p (b_p . g)
// m_p over the kernel's points p of n_p samples with mean m_p), from the rows the search kept:
//  - noise: sigma^2 sum_p n_p w_p^2 (b_p . g)^2, with the per-sample residual variance
//    sigma^2 = sum_p w_p n_p r_p^2 / sum_p w_p (a bin mean's residual has variance sigma^2 / n_p)
//    times P / (P - m), P = (sum w)^2 / sum w^2 the kernel's effective point count (degrees of freedom);
//  - bias: the same degree refitted in the kernel shrunk by `shrink` (the same rows, tricube weights of
//    r / shrink) differs from the estimate by about bias (1 - shrink^(degree + 1)) for a bias of order
//    h^(degree + 1) (local polynomial regression's leading term, Fan and Gijbels 1996, section 3.2);
//    the squared difference less its own noise, sigma^2 sum_p n_p (w_p b_p . g - w'_p b_p . g')^2,
//    floored at 0, divided by (1 - shrink^(degree + 1))^2. Where the shrunk kernel cannot carry the
//    degree (too few samples, ill-conditioned), the disagreement with the next lower degree in the
//    full kernel stands for the bias (larger than the fit's own: conservative), and for degree 0 half
//    the neighbours' value range.
// Per channel, in the fitting space.
struct ErrorParts {
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();  // of the noise
  Eigen::Vector3d bias2 = Eigen::Vector3d::Zero();     // squared bias
  bool shrunk = false;  // the bias is the shrunk kernel's (false: a stand-in, see above)
};
ErrorParts StandardErrors(const NormalEquations& eq, const LocalRegressionOptions& options, int degree,
                               const double coefficients[kMaxCoefficients][3], const double* g,
                               const double lower_value[3], double growth) {
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCoefficients, kMaxCoefficients>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1>;
  const int m = kCoefficients[degree];
  const int kRow = NormalEquations::kRowSize;
  const double* rows = eq.rows->data();
  const size_t count = eq.rows_used / kRow;
  double residual[3] = {0, 0, 0}, sum_w = 0.0, sum_w2 = 0.0;
  const double shrink = options.bias_shrink;
  Matrix a = Matrix::Zero(m, m);
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxCoefficients, 3> b =
      Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxCoefficients, 3>::Zero(m, 3);
  double small_w = 0.0, small_w2 = 0.0;
  for (size_t p = 0; p < count; ++p) {
    const double* row = rows + p * kRow;
    const double nw2 = row[NormalEquations::kSquaredWeight], nw = row[NormalEquations::kWeight];
    if (!(nw > 0.0)) continue;
    const double w = nw2 / nw, n = nw * nw / nw2;
    const double* basis = row + NormalEquations::kBasis;
    for (int c = 0; c < 3; ++c) {
      double fitted = 0.0;
      for (int i = 0; i < m; ++i) fitted += basis[i] * coefficients[i][c];
      const double r = row[NormalEquations::kMean + c] - fitted;
      residual[c] += nw * r * r;
    }
    sum_w += w;
    sum_w2 += w * w;
    // The shrunk kernel's weight from the offsets in support radii (basis 1..3).
    const double r2 = (basis[1] * basis[1] + basis[2] * basis[2] + basis[3] * basis[3]) / (shrink * shrink);
    if (r2 >= 1.0) continue;
    const double t = 1.0 - r2 * std::sqrt(r2);
    const double ws = n * t * t * t;
    small_w += ws;
    small_w2 += ws * t * t * t;
    for (int i = 0; i < m; ++i) {
      for (int j = i; j < m; ++j) a(i, j) += ws * basis[i] * basis[j];
      for (int c = 0; c < 3; ++c) b(i, c) += ws * basis[i] * row[NormalEquations::kMean + c];
    }
  }
  Eigen::Vector3d sigma2;
  const double points = sum_w2 > 0.0 ? sum_w * sum_w / sum_w2 : 0.0;
  const double dof = points > m + 1.0 ? points / (points - m) : std::max(points, 1.0);
  for (int c = 0; c < 3; ++c) sigma2[c] = sum_w > 0.0 ? residual[c] / sum_w * dof : 0.0;
  const double relative_variance = eq.Variance(g, m);
  Eigen::Vector3d variance = sigma2 * relative_variance;

  // The shrunk kernel's fit of the same degree.
  Eigen::Vector3d bias2 = Eigen::Vector3d::Zero();
  bool shrunk = false;
  if (small_w > 0.0 && small_w * small_w / small_w2 >= options.min_samples_per_coefficient * m) {
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < i; ++j) a(i, j) = a(j, i);
    }
    const Eigen::LDLT<Matrix> ldlt(a);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() && ldlt.rcond() > options.min_rcond) {
      Vector e1 = Vector::Zero(m);
      e1[0] = 1.0;
      const Vector gs = ldlt.solve(e1).eval();
      const auto cs = ldlt.solve(b).eval();
      double difference_variance = 0.0, small_variance = 0.0;
      for (size_t p = 0; p < count; ++p) {
        const double* row = rows + p * kRow;
        const double nw2 = row[NormalEquations::kSquaredWeight], nw = row[NormalEquations::kWeight];
        if (!(nw > 0.0)) continue;
        const double w = nw2 / nw, n = nw * nw / nw2;
        const double* basis = row + NormalEquations::kBasis;
        const double r2 = (basis[1] * basis[1] + basis[2] * basis[2] + basis[3] * basis[3]) / (shrink * shrink);
        double ws = 0.0;
        if (r2 < 1.0) {
          const double t = 1.0 - r2 * std::sqrt(r2);
          ws = t * t * t;
        }
        double lg = 0.0, ls = 0.0;
        for (int i = 0; i < m; ++i) {
          lg += basis[i] * g[i];
          ls += basis[i] * gs[i];
        }
        difference_variance += n * (w * lg - ws * ls) * (w * lg - ws * ls);
        small_variance += n * ws * ws * ls * ls;
      }
      if (small_variance > 0.0 && 1.0 / small_variance >= options.min_fit_samples) {
        shrunk = true;
        const double order = 1.0 - std::pow(shrink, degree + 1);
        for (int c = 0; c < 3; ++c) {
          const double d = coefficients[0][c] - cs(0, c);
          bias2[c] = std::max(0.0, d * d - sigma2[c] * difference_variance) / (order * order);
        }
      }
    }
  }
  if (!shrunk) {
    for (int c = 0; c < 3; ++c) {
      const double d = degree > 0 ? coefficients[0][c] - lower_value[c] : 0.5 * (double(eq.high[c]) - eq.low[c]);
      bias2[c] = d * d;
    }
  }
  // Binning: a bin enters at its samples' centroid with their mean value, which exceeds the value at the
  // centroid by sum_k c_kk Var_k for a quadratic of diagonal coefficients c_kk (within-bin variances
  // Var_k, edge^2 / 12 for samples spread evenly over the bin). Both fits above see the same bins, so
  // this part of the bias is added on its own: at a peak a few bin edges wide it dominates.
  if (degree == 2) {
    const double h = options.bin_fraction_h / growth, d = options.bin_fraction_d / growth;
    for (int c = 0; c < 3; ++c) {
      const double binning = (coefficients[4][c] + coefficients[5][c]) * h * h / 12.0 + coefficients[6][c] * d * d / 12.0;
      bias2[c] += binning * binning;
    }
  }
  ErrorParts parts;
  parts.variance = variance;
  parts.bias2 = bias2;
  parts.shrunk = shrunk;
  return parts;
}

// The next lower degree's estimate (fitting space) from the accumulated equations: the bias's stand-in
// where the shrunk kernel cannot carry `degree` (zeros for degree 0; the local mean where the lower
// system is singular).
void LowerDegreeValue(const NormalEquations& eq, int degree, double lower[3]) {
  if (degree < 1) return;
  const int m = kCoefficients[degree - 1];
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCoefficients, kMaxCoefficients> a(m, m);
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxCoefficients, 3> b(m, 3);
  for (int i = 0; i < m; ++i) {
    for (int j = i; j < m; ++j) a(i, j) = a(j, i) = eq.a[i][j];
    for (int c = 0; c < 3; ++c) b(i, c) = eq.b[i][c];
  }
  const Eigen::LDLT<decltype(a)> ldlt(a);
  const auto coefficients = ldlt.solve(b).eval();
  for (int c = 0; c < 3; ++c) lower[c] = std::isfinite(coefficients(0, c)) ? coefficients(0, c) : eq.b[0][c] / eq.sum_w;
}

// The squared disagreement (per channel, fitting space) between the estimate (constant term
// `chosen[0]`) and the highest degree above `degree` that the accumulated (wider) kernel carries under
// the same acceptance rules as the fit; false when none does.
bool WideFitBias(const NormalEquations& eq, const LocalRegressionOptions& options, int degree,
                 const double chosen[kMaxCoefficients][3], Eigen::Vector3d* wide2) {
  const double wide_samples = eq.sum_w2 > 0.0 ? eq.sum_w * eq.sum_w / eq.sum_w2 : 0.0;
  for (int d = options.degree; d > degree; --d) {
    const int m = kCoefficients[d];
    if (wide_samples < options.min_samples_per_coefficient * m) continue;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCoefficients, kMaxCoefficients> a(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxCoefficients, 3> b(m, 3);
    for (int i = 0; i < m; ++i) {
      for (int j = i; j < m; ++j) a(i, j) = a(j, i) = eq.a[i][j];
      for (int c = 0; c < 3; ++c) b(i, c) = eq.b[i][c];
    }
    const Eigen::LDLT<decltype(a)> ldlt(a);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.rcond() > options.min_rcond)) continue;
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1> e1 =
        Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1>::Zero(m);
    e1[0] = 1.0;
    const auto g = ldlt.solve(e1).eval();
    const double variance = eq.Variance(g.data(), m);
    if (!(variance > 0.0) || 1.0 / variance < options.min_fit_samples) continue;
    const auto coefficients = ldlt.solve(b).eval();
    for (int c = 0; c < 3; ++c) {
      const double difference = chosen[0][c] - coefficients(0, c);
      (*wide2)[c] = difference * difference;
    }
    if (wide2->allFinite()) return true;
  }
  return false;
}
}  // namespace

struct LocalRegression::Impl {
  Cloud cloud;  // the points: bin centroids (every sample without binning), scaled
  // Every kept sample (scaled, folded coordinates and value) and the point it went to, for
  // leave-one-out.
  std::vector<float> sample_xyz, sample_values;
  std::vector<uint32_t> sample_point;
  std::unique_ptr<Tree> tree;
  std::vector<Mirror> mirrors;  // the identity first
  bool fold_reciprocity = false, fold_bilateral = false;
  double scale_h = 1.0, scale_d = 1.0;          // 1 / radius, per coordinate
  double theta_d_min = 0.0, theta_d_max = 0.0;  // radians, over the kept samples

  // Maps (u, v) into the canonical part of the domain.
  void Fold(double* u, double* v) const {
    if (fold_reciprocity && fold_bilateral) {
      *u = std::abs(*u);
      *v = std::abs(*v);
    } else if (fold_reciprocity) {
      if (*v < 0.0 || (*v == 0.0 && *u < 0.0)) {
        *u = -*u;
        *v = -*v;
      }
    } else if (fold_bilateral) {
      *v = std::abs(*v);
    }
  }
  // Squared distance (scaled units) from a mirrored query to the canonical region.
  double DistanceToCanonicalSquared(float x, float y) const {
    double d2 = 0.0;
    if (fold_reciprocity && fold_bilateral) {
      d2 += x < 0 ? double(x) * x : 0.0;
      d2 += y < 0 ? double(y) * y : 0.0;
    } else if (fold_reciprocity || fold_bilateral) {
      d2 += y < 0 ? double(y) * y : 0.0;
    }
    return d2;
  }
};

bool LocalRegressionOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(degree, 0, 2);
  IBRDF_CHECK_OPTION_GT(radius_h_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(radius_h_deg, 90.0);
  IBRDF_CHECK_OPTION_GT(radius_d_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(radius_d_deg, 90.0);
  IBRDF_CHECK_OPTION_GE(min_rcond, 0.0);
  IBRDF_CHECK_OPTION_LT(min_rcond, 1.0);
  IBRDF_CHECK_OPTION_GE(min_samples_per_coefficient, 1.0);
  IBRDF_CHECK_OPTION_GE(range_margin, 0.0);
  IBRDF_CHECK_OPTION_GE(min_neighbors, 1);
  IBRDF_CHECK_OPTION_GE(max_growth, 1.0);
  IBRDF_CHECK_OPTION_RANGE(bin_fraction_h, 0.0, 1.0);
  IBRDF_CHECK_OPTION_RANGE(bin_fraction_d, 0.0, 1.0);
  if (log_space) IBRDF_CHECK_OPTION_GT(log_floor, 0.0);
  IBRDF_CHECK_OPTION_GE(max_log_noise_correction, 0.0);
  IBRDF_CHECK_OPTION_GT(bias_shrink, 0.0);
  IBRDF_CHECK_OPTION_LT(bias_shrink, 1.0);
  IBRDF_CHECK_OPTION_GT(bias_wide_growth, 1.0);
  return true;
}

bool InMeasuredDomain(const Estimate& e) {
  return (e.status == EstimateStatus::kFull || e.status == EstimateStatus::kReducedDegree) &&
         e.centroid_offset <= kMeasuredDomainMaxCentroidOffset;
}

void ReliabilityCounts::Add(const Estimate& e) {
  ++evaluations;
  switch (e.status) {
    case EstimateStatus::kFull:
      ++full;
      break;
    case EstimateStatus::kReducedDegree:
      ++reduced_degree;
      break;
    case EstimateStatus::kGrown:
      ++grown;
      break;
    case EstimateStatus::kUnsupported:
      ++unsupported;
      break;
  }
  clamped += e.clamped;
  mean_effective_samples += (e.effective_samples - mean_effective_samples) / double(evaluations);
}

void ReliabilityCounts::Merge(const ReliabilityCounts& other) {
  const uint64_t total = evaluations + other.evaluations;
  if (total > 0) {
    mean_effective_samples =
        (mean_effective_samples * evaluations + other.mean_effective_samples * other.evaluations) / total;
  }
  evaluations = total;
  full += other.full;
  reduced_degree += other.reduced_degree;
  grown += other.grown;
  unsupported += other.unsupported;
  clamped += other.clamped;
}

std::string ReliabilityCounts::Brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "%llu evaluations: %llu full, %llu reduced degree, %llu grown support, %llu unsupported, %llu "
                "clamped; mean effective samples %.1f",
                (unsigned long long)evaluations, (unsigned long long)full, (unsigned long long)reduced_degree,
                (unsigned long long)grown, (unsigned long long)unsupported, (unsigned long long)clamped,
                mean_effective_samples);
  return buffer;
}

nlohmann::json ToJson(const ReliabilityCounts& counts) {
  return {{"evaluations", counts.evaluations},
          {"full", counts.full},
          {"reduced_degree", counts.reduced_degree},
          {"grown_support", counts.grown},
          {"unsupported", counts.unsupported},
          {"clamped_negative", counts.clamped},
          {"mean_effective_samples", counts.mean_effective_samples}};
}

Eigen::Vector3d RegressionCoordinates(const HalfDiffAngles& angles) {
  return {angles.theta_h * std::cos(angles.phi_d), angles.theta_h * std::sin(angles.phi_d), angles.theta_d};
}

Eigen::Vector3d RegressionCoordinates(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  HalfDiffAngles angles;
  ToHalfDiff(wi, wo, &angles);
  return RegressionCoordinates(angles);
}

namespace {

// 0, 1, ..., n - 1.
std::vector<uint32_t> Identity(size_t n) {
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  return order;
}

// Bits to hold 0..value.
int BitWidth(uint64_t value) {
  int bits = 0;
  while (value >> bits) ++bits;
  return bits;
}

// The sample indices sorted by (cell, index), lexicographically. Where the cells' ranges and the index
// fit in 64 bits (always, for real sessions), each sample is one integer key, offsets of its cell from
// the cells' minimum then its index, whose order is that of (cell, index) exactly; else the pairs.
std::vector<uint32_t> SortedByCell(const std::vector<std::array<int32_t, 3>>& cell_of) {
  const size_t n = cell_of.size();
  if (n == 0) return {};
  std::array<int32_t, 3> low = cell_of[0], high = cell_of[0];
  for (const std::array<int32_t, 3>& cell : cell_of) {
    for (int k = 0; k < 3; ++k) {
      low[k] = std::min(low[k], cell[k]);
      high[k] = std::max(high[k], cell[k]);
    }
  }
  int bits[3], index_bits = BitWidth(n - 1);
  for (int k = 0; k < 3; ++k) bits[k] = BitWidth(uint64_t(int64_t(high[k]) - low[k]));
  std::vector<uint32_t> order(n);
  if (bits[0] + bits[1] + bits[2] + index_bits <= 64) {
    std::vector<uint64_t> keys(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        uint64_t key = 0;
        for (int k = 0; k < 3; ++k) key = (key << bits[k]) | uint64_t(int64_t(cell_of[i][k]) - low[k]);
        keys[i] = (key << index_bits) | i;
      }
    });
    tbb::parallel_sort(keys.begin(), keys.end());
    const uint64_t mask = index_bits == 0 ? 0 : ~uint64_t(0) >> (64 - index_bits);
    for (size_t r = 0; r < n; ++r) order[r] = static_cast<uint32_t>(keys[r] & mask);
    return order;
  }
  using Keyed = std::pair<std::array<int32_t, 3>, uint32_t>;
  std::vector<Keyed> keyed(n);
  for (size_t i = 0; i < n; ++i) keyed[i] = {cell_of[i], static_cast<uint32_t>(i)};
  tbb::parallel_sort(keyed.begin(), keyed.end());
  for (size_t r = 0; r < n; ++r) order[r] = keyed[r].second;
  return order;
}

// The samples a channel's own regression uses: those that measured channel c, with its value in all
// three channels (so the regression's three channels are one).
std::vector<BrdfSample> ChannelSamples(const std::vector<BrdfSample>& samples, int c,
                                       const std::vector<uint8_t>* leave_out) {
  std::vector<BrdfSample> out;
  for (size_t i = 0; i < samples.size(); ++i) {
    const BrdfSample& s = samples[i];
    if (!s.valid[c] || (leave_out && (*leave_out)[i])) continue;
    BrdfSample t = s;
    for (int k = 0; k < 3; ++k) {
      t.brdf[k] = s.brdf[c];
      t.sigma[k] = s.sigma[c];
      t.valid[k] = 1;
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace

LocalRegression::LocalRegression(const std::vector<BrdfSample>& samples, const LocalRegressionOptions& options)
    : impl_(std::make_unique<Impl>()), options_(options) {
  Build(samples, nullptr);
}

LocalRegression::LocalRegression(const std::vector<BrdfSample>& samples, const std::vector<uint8_t>& leave_out,
                                 const LocalRegressionOptions& options)
    : impl_(std::make_unique<Impl>()), options_(options) {
  IBRDF_CHECK(leave_out.size() == samples.size())
      << "leave_out has " << leave_out.size() << " flags for " << samples.size() << " samples";
  Build(samples, &leave_out);
}

// Long on purpose: the per-sample loops share locals and run hot, and pieces would cost calls and copies.
void LocalRegression::Build(const std::vector<BrdfSample>& all_samples, const std::vector<uint8_t>* leave_out) {
  const LocalRegressionOptions& options = options_;
  std::string why;
  if (!options.Check(&why)) ThrowError("local regression options", why);
  const auto left_out = [leave_out](size_t i) { return leave_out && (*leave_out)[i] != 0; };
  size_t included = all_samples.size();
  // Per-channel validity: channels some samples did not measure get their own regression; in the shared
  // one their values are replaced by a fully measured channel's (so an unmeasured value cannot sway the
  // shared fit's degree or range checks), or left as they are when no channel is fully measured.
  uint64_t unmeasured[3] = {0, 0, 0};
  for (size_t i = 0; i < all_samples.size(); ++i) {
    if (left_out(i)) {
      --included;
      continue;
    }
    for (int c = 0; c < 3; ++c) unmeasured[c] += all_samples[i].valid[c] == 0;
  }
  int full = -1;
  for (int c = 0; c < 3; ++c) {
    if (unmeasured[c] == 0 && full < 0) full = c;
  }
  std::vector<BrdfSample> replaced;
  if (unmeasured[0] + unmeasured[1] + unmeasured[2] > 0) {
    for (int c = 0; c < 3; ++c) {
      if (unmeasured[c] > 0) {
        channel_regressions_[c] = std::make_unique<LocalRegression>(ChannelSamples(all_samples, c, leave_out), options);
      }
    }
    if (full >= 0) {
      replaced = all_samples;
      for (BrdfSample& s : replaced) {
        for (int c = 0; c < 3; ++c) {
          if (unmeasured[c] > 0) s.brdf[c] = s.brdf[full];
        }
      }
    }
  }
  const std::vector<BrdfSample>& samples = replaced.empty() ? all_samples : replaced;
  Impl& impl = *impl_;
  impl.fold_reciprocity = options.fold_reciprocity;
  impl.fold_bilateral = options.fold_bilateral;
  impl.scale_h = 1.0 / (options.radius_h_deg * kDegree);
  impl.scale_d = 1.0 / (options.radius_d_deg * kDegree);
  impl.mirrors.push_back({1, 1});
  if (impl.fold_reciprocity) impl.mirrors.push_back({-1, -1});
  if (impl.fold_bilateral) impl.mirrors.push_back({1, -1});
  if (impl.fold_reciprocity && impl.fold_bilateral) impl.mirrors.push_back({-1, 1});

  const size_t n = samples.size();
  std::vector<float> xyz(3 * n), values(3 * n);
  std::vector<uint8_t> valid(n, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      if (left_out(i)) continue;
      const BrdfSample& s = samples[i];
      const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
      const Eigen::Vector3f f(s.brdf[0], s.brdf[1], s.brdf[2]);
      if (!wi.allFinite() || !wo.allFinite() || !f.allFinite() || !(wi.norm() > 0.5) || !(wo.norm() > 0.5)) continue;
      HalfDiffAngles angles;
      if (!ToHalfDiff(wi.normalized(), wo.normalized(), &angles)) continue;
      Eigen::Vector3d uvw = RegressionCoordinates(angles);
      impl.Fold(&uvw[0], &uvw[1]);
      xyz[3 * i + 0] = static_cast<float>(uvw[0] * impl.scale_h);
      xyz[3 * i + 1] = static_cast<float>(uvw[1] * impl.scale_h);
      xyz[3 * i + 2] = static_cast<float>(uvw[2] * impl.scale_d);
      for (int c = 0; c < 3; ++c) {
        if (!options.log_space) {
          values[3 * i + c] = f[c];
          continue;
        }
        double value = std::log(std::max<float>(f[c], float(options.log_floor)));
        if (options.log_noise_correction && s.sigma[c] > 0.0f && f[c] > 0.0f) {
          const double relative = double(s.sigma[c]) / f[c];
          value += std::min(0.5 * relative * relative, options.max_log_noise_correction);
        }
        values[3 * i + c] = static_cast<float>(value);
      }
      valid[i] = 1;
    }
  });
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    for (int k = 0; k < 3; ++k) {
      xyz[3 * kept + k] = xyz[3 * i + k];
      values[3 * kept + k] = values[3 * i + k];
    }
    ++kept;
  }
  skipped_ = included - kept;
  xyz.resize(3 * kept);
  values.resize(3 * kept);
  xyz.shrink_to_fit();
  values.shrink_to_fit();

  // Bins: the samples in order of their cell (three int32 indices; unique per sample without binning) and
  // then of their index, one point per run of equal cells.
  const bool binning = options.bin_fraction_h > 0.0 && options.bin_fraction_d > 0.0;
  std::vector<std::array<int32_t, 3>> cell_of(kept);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, kept, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      std::array<int32_t, 3> cell = {static_cast<int32_t>(i), 0, 0};
      if (binning) {
        for (int k = 0; k < 3; ++k) {
          const double edge = k < 2 ? options.bin_fraction_h : options.bin_fraction_d;
          cell[k] = static_cast<int32_t>(std::clamp(std::floor(xyz[3 * i + k] / edge), -2.0e9, 2.0e9));
        }
      }
      cell_of[i] = cell;
    }
  });
  const std::vector<uint32_t> order = binning ? SortedByCell(cell_of) : Identity(kept);
  // Where each run of equal cells begins (in `order`), then each run's point, TBB-parallel: a run's sums
  // run over its samples in order, as the one-thread loop did.
  std::vector<size_t> runs;
  for (size_t r = 0; r < kept; ++r) {
    if (r == 0 || cell_of[order[r]] != cell_of[order[r - 1]]) runs.push_back(r);
  }
  runs.push_back(kept);
  impl.sample_point.resize(kept);
  impl.cloud.points.resize(runs.size() - 1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, runs.size() - 1, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t point = range.begin(); point != range.end(); ++point) {
      const size_t begin = runs[point], end = runs[point + 1];
      double centroid[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
      float low[3] = {0, 0, 0}, high[3] = {0, 0, 0};
      for (size_t r = begin; r < end; ++r) {
        const uint32_t i = order[r];
        impl.sample_point[i] = static_cast<uint32_t>(point);
        for (int k = 0; k < 3; ++k) {
          centroid[k] += xyz[3 * i + k];
          const float f = values[3 * i + k];
          mean[k] += f;
          low[k] = r == begin ? f : std::min(low[k], f);
          high[k] = r == begin ? f : std::max(high[k], f);
        }
      }
      const double count = double(end - begin);
      Point& p = impl.cloud.points[point];
      for (int k = 0; k < 3; ++k) {
        p.xyz[k] = static_cast<float>(centroid[k] / count);
        p.value[k] = static_cast<float>(mean[k] / count);
        p.low[k] = low[k];
        p.high[k] = high[k];
      }
      p.count = static_cast<uint32_t>(end - begin);
    }
  });
  if (kept > 0) {
    float low = xyz[2], high = xyz[2];
    for (size_t i = 1; i < kept; ++i) {
      low = std::min(low, xyz[3 * i + 2]);
      high = std::max(high, xyz[3 * i + 2]);
    }
    impl.theta_d_min = low / impl.scale_d;
    impl.theta_d_max = high / impl.scale_d;
  }
  impl.sample_xyz = std::move(xyz);
  impl.sample_values = std::move(values);
  impl.tree = std::make_unique<Tree>(3, impl.cloud, nanoflann::KDTreeSingleIndexAdaptorParams(24));
  if (kept > 0) impl.tree->buildIndex();
  // The points in the tree's leaf order (a leaf's points contiguous, so a search reads whole cache lines
  // of neighbours, not points scattered over the array): the tree itself is unchanged, so every search
  // visits the same points in the same order, with their indices renumbered (docs/decisions.md).
  std::vector<Point> ordered(impl.cloud.points.size());
  std::vector<uint32_t> renumbered(impl.cloud.points.size());
  for (size_t k = 0; k < impl.tree->vAcc.size(); ++k) {
    ordered[k] = impl.cloud.points[impl.tree->vAcc[k]];
    renumbered[impl.tree->vAcc[k]] = static_cast<uint32_t>(k);
    impl.tree->vAcc[k] = static_cast<uint32_t>(k);
  }
  impl.cloud.points = std::move(ordered);
  for (uint32_t& point : impl.sample_point) point = renumbered[point];
}

LocalRegression::~LocalRegression() = default;

size_t LocalRegression::size() const { return impl_->sample_values.size() / 3; }

size_t LocalRegression::points() const { return impl_->cloud.points.size(); }

double LocalRegression::theta_d_min() const { return impl_->theta_d_min; }

double LocalRegression::theta_d_max() const { return impl_->theta_d_max; }

int LocalRegression::separate_channels() const {
  int bits = 0;
  for (int c = 0; c < 3; ++c) bits |= channel_regressions_[c] ? 1 << c : 0;
  return bits;
}

Estimate LocalRegression::EvaluateAt(const Eigen::Vector3d& uvw, int64_t exclude) const {
  Estimate estimate = Fit(uvw, exclude, -1, nullptr);
  for (int c = 0; c < 3; ++c) {
    if (!channel_regressions_[c]) continue;
    const Estimate e = channel_regressions_[c]->EvaluateAt(uvw);
    estimate.value[c] = e.value[c];
    estimate.standard_error[c] = e.standard_error[c];
    // The least favourable reliability over the channels.
    estimate.effective_samples = std::min(estimate.effective_samples, e.effective_samples);
    estimate.rcond = std::min(estimate.rcond, e.rcond);
    estimate.growth = std::max(estimate.growth, e.growth);
    estimate.centroid_offset = std::max(estimate.centroid_offset, e.centroid_offset);
    estimate.nearest = std::max(estimate.nearest, e.nearest);
    estimate.neighbors = std::min(estimate.neighbors, e.neighbors);
    estimate.degree = std::min(estimate.degree, e.degree);
    estimate.status = std::max(estimate.status, e.status);
    estimate.clamped = estimate.clamped || e.clamped;
  }
  return estimate;
}

Estimate LocalRegression::Evaluate(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  return EvaluateAt(RegressionCoordinates(wi, wo));
}

Estimate LocalRegression::Evaluate(const HalfDiffAngles& angles) const {
  return EvaluateAt(RegressionCoordinates(angles));
}

Estimate LocalRegression::Fit(const Eigen::Vector3d& uvw_in, int64_t exclude, int64_t self, double* leverage) const {
  const Impl& impl = *impl_;
  Estimate estimate;
  if (leverage) *leverage = 0.0;
  if (size() == 0 || !uvw_in.allFinite()) return estimate;
  double u = uvw_in[0], v = uvw_in[1];
  impl.Fold(&u, &v);
  const float x = static_cast<float>(u * impl.scale_h);
  const float y = static_cast<float>(v * impl.scale_h);
  const float z = static_cast<float>(uvw_in[2] * impl.scale_d);

  NormalEquations eq;
  thread_local std::vector<double> rows;  // reused across evaluations: no allocation per fit
  eq.rows = &rows;
  eq.cloud = impl.cloud.points.data();
  if (exclude >= 0 && size_t(exclude) < size()) {
    eq.exclude = impl.sample_point[size_t(exclude)];
    eq.exclude_xyz = &impl.sample_xyz[3 * size_t(exclude)];
    eq.exclude_value = &impl.sample_values[3 * size_t(exclude)];
  }
  if (self >= 0 && size_t(self) < size()) eq.self = impl.sample_point[size_t(self)];
  const nanoflann::SearchParams params(32, 0.0f, false);
  eq.enough_count = static_cast<uint32_t>(std::max(options_.min_neighbors, 0));
  // One pass over the support of radius `growth` (every mirror image); false when a count-only pass
  // stopped early because the support suffices.
  auto search = [&](float growth, bool count_only) {
    eq.Reset();
    eq.count_only = count_only;
    eq.radius = growth;
    eq.radius_squared = growth * growth;
    for (const Mirror& m : impl.mirrors) {
      const float qx = m.su * x, qy = m.sv * y;
      if (impl.DistanceToCanonicalSquared(qx, qy) >= double(growth) * growth) continue;
      eq.query[0] = qx;
      eq.query[1] = qy;
      eq.query[2] = z;
      eq.mirror = m;
      impl.tree->findNeighbors(eq, eq.query, params);
      if (count_only && eq.count >= eq.enough_count && eq.sum_w > 0.0) return;
    }
  };
  // The given radius is accumulated at once (most evaluations end there). A grown support is first
  // only counted (the search stops as soon as it suffices) and accumulated once, at the radius that
  // suffices or the largest: the same equations as accumulating at every step, at a fraction of the
  // cost where the support has to grow far.
  float growth = 1.0f;
  search(growth, false);
  for (;;) {
    const bool enough = int(eq.count) >= options_.min_neighbors && eq.sum_w > 0.0;
    if (enough || growth >= options_.max_growth) {
      if (eq.count_only && eq.sum_w > 0.0) search(growth, false);
      break;
    }
    growth = std::min<float>(growth * 1.5f, float(options_.max_growth));
    search(growth, true);
  }
  eq.Accumulate();
  if (!(eq.sum_w > 0.0)) return estimate;  // unsupported: value 0, degree -1

  estimate.neighbors = eq.count;
  estimate.growth = growth;
  estimate.centroid_offset = static_cast<float>(
      growth * std::sqrt(eq.a[0][1] * eq.a[0][1] + eq.a[0][2] * eq.a[0][2] + eq.a[0][3] * eq.a[0][3]) / eq.sum_w);
  estimate.effective_samples = static_cast<float>(eq.sum_w * eq.sum_w / eq.sum_w2);
  estimate.nearest = std::sqrt(eq.nearest_squared);  // the tree is in given-radius units
  // The accepted degree's coefficients (fitting space) and weights g = A^-1 e1, for its standard error.
  double chosen_coefficients[kMaxCoefficients][3] = {};
  double chosen_g[kMaxCoefficients] = {};
  for (int degree = options_.degree; degree >= 0; --degree) {
    const int m = kCoefficients[degree];
    Eigen::Vector3d value;
    double rcond = 1.0;
    double fit_samples = eq.sum_w * eq.sum_w / eq.sum_w2;
    double self_weight = 0.0;  // l_ii: the weight of sample `self` in this degree's estimate
    if (degree == 0) {
      value = Eigen::Vector3d(eq.b[0][0], eq.b[0][1], eq.b[0][2]) / eq.sum_w;
      self_weight = eq.self_basis[0] / eq.sum_w;
      for (int c = 0; c < 3; ++c) chosen_coefficients[0][c] = value[c];
      chosen_g[0] = 1.0 / eq.sum_w;
    } else {
      if (estimate.effective_samples < options_.min_samples_per_coefficient * m) continue;
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCoefficients, kMaxCoefficients> a(m, m);
      Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxCoefficients, 3> b(m, 3);
      for (int i = 0; i < m; ++i) {
        for (int j = i; j < m; ++j) a(i, j) = a(j, i) = eq.a[i][j];
        for (int c = 0; c < 3; ++c) b(i, c) = eq.b[i][c];
      }
      const Eigen::LDLT<decltype(a)> ldlt(a);
      if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
      rcond = ldlt.rcond();
      if (!(rcond > options_.min_rcond)) continue;
      // The estimate is sum_i l_i f_i; its variance relative to one sample's is sum l_i^2 =
      // g' A2 g with g = A^-1 e1. An extrapolation along a poorly sampled direction (one sheet, a domain
      // edge) has huge weights l_i: too few effective samples, so a lower degree is used.
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1> e1 =
          Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxCoefficients, 1>::Zero(m);
      e1[0] = 1.0;
      const auto g = ldlt.solve(e1).eval();
      const double variance = eq.Variance(g.data(), m);
      if (!(variance > 0.0) || 1.0 / variance < options_.min_fit_samples) continue;
      fit_samples = 1.0 / variance;
      for (int i = 0; i < m; ++i) self_weight += eq.self_basis[i] * g[i];
      const auto coefficients = ldlt.solve(b).eval();
      value = coefficients.row(0).transpose();
      // An estimate far outside the range of the values it was fitted to is an extrapolation along a
      // poorly sampled direction (one sheet, a domain edge): use a lower degree instead.
      bool in_range = true;
      for (int c = 0; c < 3; ++c) {
        const double margin = options_.range_margin * (double(eq.high[c]) - eq.low[c]);
        in_range = in_range && value[c] >= eq.low[c] - margin && value[c] <= eq.high[c] + margin;
      }
      if (!in_range) continue;
      for (int i = 0; i < m; ++i) {
        chosen_g[i] = g[i];
        for (int c = 0; c < 3; ++c) chosen_coefficients[i][c] = coefficients(i, c);
      }
    }
    if (options_.log_space) value = value.array().exp();
    if (!value.allFinite()) continue;
    estimate.value = value;
    estimate.rcond = static_cast<float>(rcond);
    estimate.effective_samples = static_cast<float>(fit_samples);
    estimate.degree = static_cast<int8_t>(degree);
    if (leverage) *leverage = self_weight;
    break;
  }
  if (estimate.degree < 0) return Estimate();  // cannot happen: degree 0 is always finite here
  if (options_.standard_errors && exclude < 0 && self < 0) {
    double lower[3] = {0, 0, 0};
    LowerDegreeValue(eq, estimate.degree, lower);
    ErrorParts parts = StandardErrors(eq, options_, estimate.degree, chosen_coefficients, chosen_g, lower, growth);
    if (estimate.degree < options_.degree && growth <= 1.0f) {
      // A reduced degree leaves a direction unresolved (one sheet of samples across w: the local constant
      // or plane cannot see theta_d's trend, and neither can a shrunk kernel). The requested degree
      // fitted in a kernel bias_wide_growth times as large, where more sheets take part, gives the
      // trend: its disagreement with the estimate stands for the estimate's bias (plus the larger fit's
      // own bias: conservative). Where even that kernel cannot carry a higher degree, the stand-in stays.
      search(float(options_.bias_wide_growth), false);
      eq.Accumulate();
      Eigen::Vector3d wide2;
      if (WideFitBias(eq, options_, estimate.degree, chosen_coefficients, &wide2)) {
        parts.bias2 = parts.shrunk ? parts.bias2.cwiseMax(wide2) : wide2;
      }
    }
    Eigen::Vector3d error = (parts.variance + parts.bias2).cwiseSqrt();
    if (!options_.log_space) {
      // Relative: the standard error of f over f (infinite at 0).
      for (int c = 0; c < 3; ++c) {
        error[c] = estimate.value[c] > 0.0 ? error[c] / estimate.value[c] : std::numeric_limits<double>::infinity();
      }
    }
    for (int c = 0; c < 3; ++c) {
      estimate.standard_error[c] =
          std::isfinite(error[c]) ? static_cast<float>(error[c]) : std::numeric_limits<float>::infinity();
    }
  }
  if (options_.clamp_negative && (estimate.value.array() < 0.0).any()) {
    estimate.value = estimate.value.cwiseMax(0.0);
    estimate.clamped = true;
  }
  if (growth > 1.0f) {
    estimate.status = EstimateStatus::kGrown;
  } else if (estimate.degree < options_.degree) {
    estimate.status = EstimateStatus::kReducedDegree;
  } else {
    estimate.status = EstimateStatus::kFull;
  }
  return estimate;
}

std::vector<Estimate> LocalRegression::EvaluateMany(const std::vector<Eigen::Vector3d>& uvw,
                                                    ReliabilityCounts* counts) const {
  std::vector<Estimate> estimates(uvw.size());
  std::mutex mutex;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, uvw.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    ReliabilityCounts local;
    for (size_t i = range.begin(); i != range.end(); ++i) {
      estimates[i] = EvaluateAt(uvw[i]);
      local.Add(estimates[i]);
    }
    if (counts) {
      std::lock_guard<std::mutex> lock(mutex);
      counts->Merge(local);
    }
  });
  return estimates;
}

CrossValidationScore LocalRegression::CrossValidate(size_t count, uint64_t seed) const {
  if (separate_channels() == 0) return CrossValidateShared(count, seed);
  // Each channel scored by the regression that serves it, weighted by the channels it serves.
  CrossValidationScore score;
  int shared_channels = 0;
  for (int c = 0; c < 3; ++c) shared_channels += channel_regressions_[c] ? 0 : 1;
  std::vector<std::pair<CrossValidationScore, double>> parts;
  if (shared_channels > 0) parts.push_back({CrossValidateShared(count, seed), shared_channels / 3.0});
  for (int c = 0; c < 3; ++c) {
    if (channel_regressions_[c]) parts.push_back({channel_regressions_[c]->CrossValidate(count, seed), 1.0 / 3.0});
  }
  double loo = 0.0, residual = 0.0, gcv = 0.0;
  for (const auto& [part, weight] : parts) {
    score.points = std::max(score.points, part.points);
    loo += weight * part.loo_rms * part.loo_rms;
    residual += weight * part.residual_rms * part.residual_rms;
    gcv += weight * part.gcv_rms * part.gcv_rms;
    score.mean_leverage += weight * part.mean_leverage;
  }
  score.loo_rms = std::sqrt(loo);
  score.residual_rms = std::sqrt(residual);
  score.gcv_rms = std::sqrt(gcv);
  return score;
}

CrossValidationScore LocalRegression::CrossValidateShared(size_t count, uint64_t seed) const {
  CrossValidationScore score;
  const size_t n = size();
  if (n == 0) return score;
  count = std::min(count, n);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  std::vector<size_t> indices(count);
  for (size_t& index : indices) index = pick(rng);
  // Per scored sample: squared leave-one-out residual, squared ordinary residual (summed over channels)
  // and leverage.
  std::vector<Eigen::Vector3d> sums(count);
  const Impl& impl = *impl_;
  const double floor = options_.log_floor;
  auto residual = [&](double estimate, double stored) {
    if (options_.log_space) return std::log(std::max(estimate, floor)) - stored;
    return (estimate - stored) / std::max(std::abs(stored), 1e-4);
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const size_t i = indices[k];
      const float* p = &impl.sample_xyz[3 * i];
      const Eigen::Vector3d uvw(p[0] / impl.scale_h, p[1] / impl.scale_h, p[2] / impl.scale_d);
      const Estimate out = Fit(uvw, static_cast<int64_t>(i), -1, nullptr);
      double leverage = 0.0;
      const Estimate in = Fit(uvw, -1, static_cast<int64_t>(i), &leverage);
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) {
        const double stored = impl.sample_values[3 * i + c];
        s[0] += std::pow(residual(out.value[c], stored), 2);
        s[1] += std::pow(residual(in.value[c], stored), 2);
      }
      s[2] = leverage;
      sums[k] = s;
    }
  });
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& s : sums) total += s;
  score.points = count;
  score.loo_rms = std::sqrt(total[0] / (3.0 * count));
  score.residual_rms = std::sqrt(total[1] / (3.0 * count));
  score.mean_leverage = total[2] / double(count);
  score.gcv_rms = score.mean_leverage < 1.0 ? score.residual_rms / (1.0 - score.mean_leverage)
                                            : std::numeric_limits<double>::infinity();
  return score;
}

}  // namespace ibrdf
