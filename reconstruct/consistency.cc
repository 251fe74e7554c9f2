#include "reconstruct/consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/kind.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"
#include "reconstruct/prediction_check.h"

namespace ibrdf {
namespace {

// A point of the isotropic domain embedded so that distances are angles: (theta_i, theta_e cos dphi,
// theta_e sin dphi), radians (the exitant direction's azimuthal-equidistant projection in the frame where
// the light has azimuth 0).
Eigen::Vector3d Embed(double theta_i, double theta_e, double delta_phi) {
  return {theta_i, theta_e * std::cos(delta_phi), theta_e * std::sin(delta_phi)};
}

// The symmetry a figure tests: the image of a configuration under it.
enum class Symmetry { kReciprocity, kBilateral };

Eigen::Vector3d Image(Symmetry symmetry, const BrdfSample& s) {
  switch (symmetry) {
    case Symmetry::kReciprocity:
      return Embed(s.theta_e, s.theta_i, -s.delta_phi);
    case Symmetry::kBilateral:
      return Embed(s.theta_i, s.theta_e, -s.delta_phi);
  }
  UnhandledKind("Symmetry", int(symmetry));
}

// The samples in a grid of cells `cell` radians wide, for neighbourhood queries: the usable samples
// sorted by cell (x, y, z) and index, so a column of cells (x, y) is one run of the arrays, found by a
// dense (x, y) table, and its cells z - 1 .. z + 1 one stretch of it. Each entry keeps its embedded
// point, the embedded point of its reciprocal configuration (the mirrored one is the point reflected
// in z), and its value and log.
class SampleGrid {
 public:
  SampleGrid(const std::vector<BrdfSample>& samples, const std::vector<uint32_t>& usable, double cell) : cell_(cell) {
    const size_t n = usable.size();
    if (n == 0) return;
    // One cosine and sine of delta_phi per sample give all three embedded points (Embed, Image): the
    // point (theta_i, theta_e c, theta_e s), its reciprocal (theta_e, theta_i c, -theta_i s) and its
    // mirror (theta_i, theta_e c, -theta_e s), bit for bit as Embed computes them (cos is even, sin odd).
    // Computed twice, for the cells and for the sorted entries, rather than kept in a second copy of
    // the entries (whose fresh pages cost more than the sines).
    auto point_of = [&](const BrdfSample& s, double* c, double* sn) {
      *c = std::cos(double(s.delta_phi));
      *sn = std::sin(double(s.delta_phi));
      return Eigen::Vector3d(s.theta_i, s.theta_e * *c, s.theta_e * *sn);
    };
    std::vector<Eigen::Vector3i> cells(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
      double c, sn;
      for (size_t i = range.begin(); i < range.end(); ++i) cells[i] = Cell(point_of(samples[usable[i]], &c, &sn));
    });
    lo_ = hi_ = cells[0].head<2>();
    for (const Eigen::Vector3i& c : cells) {
      lo_ = lo_.cwiseMin(c.head<2>());
      hi_ = hi_.cwiseMax(c.head<2>());
    }
    size_x_ = hi_.x() - lo_.x() + 1;
    size_y_ = hi_.y() - lo_.y() + 1;
    // Sorted by (x, y, z), then by sample index: two stable counting sorts, by z and then by column, so
    // that within a cell the samples keep their file order and the sums over a neighbourhood add them
    // in the same order on any thread count (the same bits).
    int z_lo = cells[0].z(), z_hi = cells[0].z();
    for (const Eigen::Vector3i& c : cells) {
      z_lo = std::min(z_lo, c.z());
      z_hi = std::max(z_hi, c.z());
    }
    std::vector<uint32_t> by_z(n), order(n);
    {
      std::vector<size_t> next(size_t(z_hi - z_lo) + 2, 0);
      for (size_t i = 0; i < n; ++i) ++next[size_t(cells[i].z() - z_lo) + 1];
      for (size_t z = 1; z < next.size(); ++z) next[z] += next[z - 1];
      for (size_t i = 0; i < n; ++i) by_z[next[size_t(cells[i].z() - z_lo)]++] = uint32_t(i);
    }
    columns_.assign(size_t(size_x_) * size_y_ + 1, 0);
    for (size_t i = 0; i < n; ++i) ++columns_[Column(cells[i]) + 1];
    for (size_t c = 1; c < columns_.size(); ++c) columns_[c] += columns_[c - 1];
    {
      std::vector<size_t> next(columns_.begin(), columns_.end() - 1);
      for (const uint32_t i : by_z) order[next[Column(cells[i])]++] = i;
    }
    // The entries filled in file order (reading the samples in sequence), each to its sorted place.
    std::vector<uint32_t>& rank = by_z;
    for (size_t k = 0; k < n; ++k) rank[order[k]] = uint32_t(k);
    entries_.resize(n);
    points_.resize(n);
    z_.resize(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) {
        const size_t k = rank[i];
        const uint32_t index = usable[i];
        const BrdfSample& s = samples[index];
        double c, sn;
        const Eigen::Vector3d point = point_of(s, &c, &sn);
        Entry& e = entries_[k];
        e.index = index;
        e.point = point.cast<float>();
        e.reciprocal = Eigen::Vector3d(s.theta_e, s.theta_i * c, -(s.theta_i * sn)).cast<float>();
        e.positive = s.brdf[0] > 0.0f && s.brdf[1] > 0.0f && s.brdf[2] > 0.0f;
        e.value = Eigen::Vector3f(s.brdf[0], s.brdf[1], s.brdf[2]);
        for (int ch = 0; ch < 3; ++ch) e.log_value[ch] = e.positive ? std::log(s.brdf[ch]) : 0.0f;
        points_[k] = e.point;
        z_[k] = cells[i].z();
      }
    });
  }

  // Single precision: the sample file's angles and values are floats.
  struct Entry {
    uint32_t index = 0;          // sample index
    bool positive = false;       // every channel's value > 0 (its log is finite)
    Eigen::Vector3f point;       // embedded point
    Eigen::Vector3f reciprocal;  // embedded point of its reciprocal configuration
    Eigen::Vector3f value;       // brdf per channel
    Eigen::Vector3f log_value;   // log brdf per channel (0 where not positive)
    // The embedded point of its image under `symmetry` (as Image computes it, in single precision).
    Eigen::Vector3f ImageOf(Symmetry symmetry) const {
      switch (symmetry) {
        case Symmetry::kReciprocity:
          return reciprocal;
        case Symmetry::kBilateral:
          return {point[0], point[1], -point[2]};
      }
      UnhandledKind("Symmetry", int(symmetry));
    }
  };

  // Calls visit(entry, squared distance) for every entry within `radius` (<= the cell size) of
  // `center`, in grid order.
  template <typename Visit>
  void ForEachWithin(const Eigen::Vector3d& center, double radius, Visit visit) const {
    const Eigen::Vector3i c = Cell(center);
    for (int x = c.x() - 1; x <= c.x() + 1; ++x) {
      if (x < lo_.x() || x > hi_.x()) continue;
      for (int y = c.y() - 1; y <= c.y() + 1; ++y) {
        if (y < lo_.y() || y > hi_.y()) continue;
        const size_t column = Column(Eigen::Vector3i(x, y, 0));
        const int *const begin = z_.data() + columns_[column], *const end = z_.data() + columns_[column + 1];
        for (const int* it = LowerBound(begin, end, c.z() - 1); it != end && *it <= c.z() + 1; ++it) {
          const size_t k = size_t(it - z_.data());
          const double squared_distance = (points_[k].cast<double>() - center).squaredNorm();
          if (squared_distance <= radius * radius) visit(entries_[k], squared_distance);
        }
      }
    }
  }

 private:
  // std::lower_bound without the branch per step (its mispredictions cost more than the columns' few
  // dozen entries): the first of [begin, end) not below `key`.
  static const int* LowerBound(const int* begin, const int* end, int key) {
    size_t n = size_t(end - begin);
    if (n == 0) return end;
    const int* base = begin;
    while (n > 1) {
      const size_t half = n / 2;
      base = base[half] < key ? base + half : base;
      n -= half;
    }
    return base + (*base < key ? 1 : 0);
  }

  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    // The embedding is bounded by pi/2 in every coordinate, so the cells fit an int.
    return {int(std::floor(p[0] / cell_)), int(std::floor(p[1] / cell_)), int(std::floor(p[2] / cell_))};
  }
  size_t Column(const Eigen::Vector3i& c) const { return size_t(c.x() - lo_.x()) * size_y_ + (c.y() - lo_.y()); }

  double cell_;
  Eigen::Vector2i lo_ = Eigen::Vector2i::Zero(), hi_ = Eigen::Vector2i::Constant(-1);  // (x, y) cells held
  int size_x_ = 0, size_y_ = 0;
  std::vector<size_t> columns_;  // column (x, y) holds entries [columns_[c], columns_[c + 1])
  std::vector<int> z_;           // z cell of each entry (increasing within a column)
  std::vector<Entry> entries_;
  std::vector<Eigen::Vector3f> points_;  // each entry's point again, packed: what a query scans
};

// The joint local fit of one pair (see consistency.h): log f = c + g . d + d^T H d / 2 + delta [A side],
// d the offset from the image point q in units of the radius, weighted least squares over the samples
// around q (side B, as measured) and those around the sample's own point p (side A, each taken to its
// image, near q). The fit shares the BRDF's slope and curvature between the sides, so delta, the log
// of A over B at q, is free of both (to third order in the radius).
class PairFit {
 public:
  static constexpr int kParams = 11;       // 1, d (3), d d^T (6), the A-side offset
  static constexpr int kMaxSamples = 128;  // samples a fit holds (FindPartner takes at most 64 a side)
  static constexpr double kCurvaturePrior = 1e-5;
  PairFit(const Eigen::Vector3d& q, double radius) : q_(q), inv_radius_(1.0 / radius) {}

  // A sample at `point` (near q) with weight `weight`. Only its design row is kept: Solve forms the
  // normal equations in one pass over the rows, by hand on the lower triangle (an 11-parameter outer
  // product per sample through Eigen's general rank update cost several times as much).
  void Add(const Eigen::Vector3f& point, const Eigen::Vector3f& log_value, bool side_a, double weight) {
    IBRDF_CHECK(rows_ < kMaxSamples);
    const Eigen::Vector3d d = (point.cast<double>() - q_) * inv_radius_;
    double* x = x_[rows_];
    x[0] = 1.0;
    x[1] = d[0];
    x[2] = d[1];
    x[3] = d[2];
    x[4] = 0.5 * d[0] * d[0];
    x[5] = 0.5 * d[1] * d[1];
    x[6] = 0.5 * d[2] * d[2];
    x[7] = d[0] * d[1];
    x[8] = d[0] * d[2];
    x[9] = d[1] * d[2];
    x[10] = side_a ? 1.0 : 0.0;
    weight_[rows_] = weight;
    for (int c = 0; c < 3; ++c) log_value_[rows_][c] = log_value[c];
    ++rows_;
    ++count_[side_a ? 1 : 0];
  }

  // The A-side offset per channel and its variance in units of one sample's. The six curvature
  // coefficients carry a ridge penalty of kCurvaturePrior times the summed weight, so that a curvature
  // the samples do not determine (across two sheets of samples) shrinks to none instead of trading
  // against delta, while one they do determine (along the sheets, where a sharp highlight bends) is
  // fitted. The variance is that of the weighted, penalized estimate (M^-1 X^T W^2 X M^-1, M the
  // penalized X^T W X), e^T M^-1 X^T W^2 X M^-1 e = sum of w^2 (x . M^-1 e)^2: 1 when side A is one
  // sample and side B's fit exact, less with more. False where the fit is singular or the variance
  // exceeds `max_variance`.
  bool Solve(double max_variance, Eigen::Vector3d* delta, double* variance) const {
    if (count_[0] + count_[1] < kParams) return false;
    // X^T W X (lower triangle) and X^T W log f, added sample by sample in Add's order.
    double normal[kParams][kParams] = {};
    double rhs[3][kParams] = {};
    for (int r = 0; r < rows_; ++r) {
      const double* x = x_[r];
      const double w = weight_[r];
      for (int i = 0; i < kParams; ++i) {
        const double wx = w * x[i];
        for (int j = i; j < kParams; ++j) normal[i][j] += wx * x[j];  // row i of the transpose: (j, i)
      }
      for (int c = 0; c < 3; ++c) {
        const double wl = w * log_value_[r][c];
        for (int j = 0; j < kParams; ++j) rhs[c][j] += wl * x[j];
      }
    }
    const double prior = kCurvaturePrior * normal[0][0];  // times the summed weight
    for (int i = 4; i < 10; ++i) normal[i][i] += prior;
    // The inverse's last column M^-1 e by Cholesky, M = L L^T, written out for the one right-hand side:
    // L y = e is y = e / L(10, 10), and L^T column = y is one back substitution.
    double l[kParams][kParams];  // l[i][j] = L(i, j), j <= i
    for (int j = 0; j < kParams; ++j) {
      double pivot = normal[j][j];
      for (int k = 0; k < j; ++k) pivot -= l[j][k] * l[j][k];
      if (!(pivot > 0.0)) return false;  // not positive definite: singular
      l[j][j] = std::sqrt(pivot);
      const double inv = 1.0 / l[j][j];
      for (int i = j + 1; i < kParams; ++i) {
        double sum = normal[j][i];  // M(i, j), i > j
        for (int k = 0; k < j; ++k) sum -= l[i][k] * l[j][k];
        l[i][j] = sum * inv;
      }
    }
    double column[kParams];
    for (int i = kParams - 1; i >= 0; --i) {
      double sum = i == kParams - 1 ? 1.0 / l[i][i] : 0.0;
      for (int k = i + 1; k < kParams; ++k) sum -= l[k][i] * column[k];
      column[i] = sum / l[i][i];
    }
    double v = 0.0;
    for (int r = 0; r < rows_; ++r) {
      double projection = 0.0;
      for (int j = 0; j < kParams; ++j) projection += x_[r][j] * column[j];
      v += weight_[r] * weight_[r] * projection * projection;
    }
    *variance = v;
    if (!(*variance > 0.0 && *variance <= max_variance)) return false;
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (int j = 0; j < kParams; ++j) sum += column[j] * rhs[c][j];
      (*delta)[c] = sum;
    }
    return std::isfinite(delta->sum());
  }

 private:
  Eigen::Vector3d q_;
  double inv_radius_;
  int rows_ = 0;
  double x_[kMaxSamples][kParams];  // the design rows, Add's order
  double weight_[kMaxSamples];
  float log_value_[kMaxSamples][3];
  int count_[2] = {0, 0};
};

// The pairs of one bin: signed relative differences and both values, per channel.
struct BinPairs {
  std::vector<double> signed_diff[3], a[3], b[3];
  size_t fitted = 0;  // pairs whose partner came from the joint fit (the others: the plain mean)
};

struct BinGrid {
  int n_theta = 0, n_phi = 0;
  double theta_step = 0, phi_step = 0;  // radians

  int Index(const BrdfSample& s) const {
    const int i = int(std::clamp(std::floor(s.theta_i / theta_step), 0.0, n_theta - 1.0));
    const int j = int(std::clamp(std::floor(s.theta_e / theta_step), 0.0, n_theta - 1.0));
    const int k = int(std::clamp(std::floor((s.delta_phi + M_PI) / phi_step), 0.0, n_phi - 1.0));
    return (i * n_theta + j) * n_phi + k;
  }
  Eigen::Vector3d CenterDeg(int index) const {
    const int k = index % n_phi, j = (index / n_phi) % n_theta, i = index / (n_phi * n_theta);
    return Eigen::Vector3d((i + 0.5) * theta_step, (j + 0.5) * theta_step, -M_PI + (k + 0.5) * phi_step) / kDegree;
  }
};

// How a pair's partner value was found.
enum class PartnerKind { kFit, kMean };

// The partner of sample `a` (entry index `index`) under `symmetry`: side B's value at a's image point
// q. Taken only where the samples within `radius` of q surround it (their centroid within
// kMaxCentroidOffset * radius: interpolation, not extrapolation; a point at the edge of the measured
// sheets gets no partner). Where side B has a sample per parameter and both sides together two, the
// value is a exp(-delta) from the joint fit (PairFit) over the samples within `radius` of q (side B)
// and of a's own point p (side A, taken to their images), at most kFitSamples of each; no partner
// where that fit leaves delta undetermined (variance above kMaxDeltaVariance times one sample's: the
// sheets of samples lie so that an offset cannot be told from a slope across them, which a mean
// would only hide). Where the samples are fewer (small radii), the plain mean of side B's samples,
// whose curvature error grows as radius^2 and is small at those radii.
bool FindPartner(const SampleGrid& grid, Symmetry symmetry, const BrdfSample& a, uint32_t index, double radius,
                 Eigen::Vector3d* b, PartnerKind* kind) {
  constexpr double kMaxCentroidOffset = 0.25;
  constexpr double kMaxDeltaVariance = 2.0;
  constexpr size_t kFitSamples = 64;
  static_assert(2 * kFitSamples <= size_t(PairFit::kMaxSamples), "a fit holds both sides' samples");
  constexpr double kMaxMeanRadiusDeg = 1.0;
  using Near = std::pair<double, const SampleGrid::Entry*>;  // squared distance, entry
  thread_local std::vector<Near> near_q, near_p;
  near_q.clear();
  near_p.clear();
  const Eigen::Vector3d q = Image(symmetry, a), p = Embed(a.theta_i, a.theta_e, a.delta_phi);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
  int around_q = 0;
  grid.ForEachWithin(q, radius, [&](const SampleGrid::Entry& e, double squared_distance) {
    if (e.index == index) return;
    centroid += e.point.cast<double>();
    sum += e.value.cast<double>();
    ++around_q;
    if (e.positive) near_q.emplace_back(squared_distance, &e);
  });
  if (around_q == 0 || (centroid / around_q - q).norm() > kMaxCentroidOffset * radius) return false;
  const bool a_positive = a.brdf[0] > 0.0f && a.brdf[1] > 0.0f && a.brdf[2] > 0.0f;
  // Side B alone must have a sample per parameter before side A is looked at (the cost of a sparse
  // neighbourhood stays that of the mean).
  if (a_positive && near_q.size() >= size_t(PairFit::kParams)) {
    grid.ForEachWithin(p, radius, [&](const SampleGrid::Entry& e, double squared_distance) {
      if (e.positive) near_p.emplace_back(squared_distance, &e);
    });
  }
  if (a_positive && near_q.size() >= size_t(PairFit::kParams) &&
      near_q.size() + near_p.size() >= 2 * PairFit::kParams) {
    // At most kFitSamples of each side, evenly through the grid order (which keeps their spread over
    // the ball, every sheet of samples in it, as the nearest would not), so the cost stays bounded.
    PairFit fit(q, radius);
    const size_t stride_q = (near_q.size() + kFitSamples - 1) / kFitSamples;
    const size_t stride_p = (near_p.size() + kFitSamples - 1) / kFitSamples;
    // The biweight kernel (1 - (distance / radius)^2)^2 about each side's own centre (floored at 1e-3
    // so that the edge samples still count): the quadratic need hold only over about half the radius,
    // where a sharp highlight's log bends least.
    const double inv_r2 = 1.0 / (radius * radius);
    auto weight = [inv_r2](double squared_distance) {
      const double u = std::max(0.0, 1.0 - squared_distance * inv_r2);
      return std::max(u * u, 1e-3);
    };
    for (size_t i = 0; i < near_q.size(); i += stride_q) {
      fit.Add(near_q[i].second->point, near_q[i].second->log_value, /*side_a=*/false, weight(near_q[i].first));
    }
    for (size_t i = 0; i < near_p.size(); i += stride_p) {
      fit.Add(near_p[i].second->ImageOf(symmetry), near_p[i].second->log_value, /*side_a=*/true,
              weight(near_p[i].first));
    }
    Eigen::Vector3d delta;
    double variance = 0.0;
    if (!fit.Solve(kMaxDeltaVariance, &delta, &variance)) return false;
    for (int c = 0; c < 3; ++c) (*b)[c] = double(a.brdf[c]) * std::exp(-delta[c]);
    *kind = PartnerKind::kFit;
    return true;
  }
  if (radius > kMaxMeanRadiusDeg * kDegree) return false;
  *b = sum / around_q;
  *kind = PartnerKind::kMean;
  return true;
}

// The standard error of a median of n values with this spread: sqrt(pi / 2) sigma / sqrt(n), sigma
// from the median absolute deviation (1.4826 MAD, the normal's), so that outliers do not inflate it.
double MedianStandardError(const std::vector<double>& values, double median) {
  std::vector<double> deviation(values.size());
  for (size_t i = 0; i < values.size(); ++i) deviation[i] = std::abs(values[i] - median);
  const double sigma = 1.4826 * PercentileInPlace(&deviation, 0.5);
  return std::sqrt(M_PI / 2.0) * sigma / std::sqrt(double(values.size()));
}

// Bins the pairs of every sample that `take` selects under `symmetry`.
template <typename Take>
ConsistencyFigure PairedFigure(const std::vector<BrdfSample>& samples, const std::vector<uint32_t>& usable,
                               const SampleGrid& grid, const BinGrid& bins, const ConsistencyOptions& options,
                               Symmetry symmetry, Take take) {
  std::unordered_map<int, BinPairs> by_bin;
  const double radius = options.match_deg * kDegree;
  // The pair fits in parallel, a block at a time into a reused buffer; the pairs are then added to their
  // bins serially in sample order (the same bins, in the same order, as the one-thread loop).
  constexpr size_t kBlock = 1 << 16;
  struct Found {
    bool paired = false;
    Eigen::Vector3d b;
    PartnerKind kind = PartnerKind::kMean;
  };
  std::vector<Found> block(std::min(kBlock, usable.size()));
  for (size_t begin = 0; begin < usable.size(); begin += kBlock) {
    const size_t end = std::min(usable.size(), begin + kBlock);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 512), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) {
        const uint32_t index = usable[i];
        const BrdfSample& a = samples[index];
        Found& found = block[i - begin];
        found.paired = take(a) && FindPartner(grid, symmetry, a, index, radius, &found.b, &found.kind);
      }
    });
    for (size_t i = begin; i < end; ++i) {
      const Found& found = block[i - begin];
      if (!found.paired) continue;
      const BrdfSample& a = samples[usable[i]];
      const Eigen::Vector3d& b = found.b;
      BinPairs& pairs = by_bin[bins.Index(a)];
      switch (found.kind) {
        case PartnerKind::kFit:
          ++pairs.fitted;
          break;
        case PartnerKind::kMean:
          break;
      }
      for (int c = 0; c < 3; ++c) {
        const double mean = 0.5 * (double(a.brdf[c]) + b[c]);
        pairs.signed_diff[c].push_back(mean > 0.0 ? (double(a.brdf[c]) - b[c]) / mean : 0.0);
        pairs.a[c].push_back(a.brdf[c]);
        pairs.b[c].push_back(b[c]);
      }
    }
  }
  std::vector<int> order;
  for (const auto& [index, pairs] : by_bin) {
    if (int(pairs.a[0].size()) >= options.min_samples_per_bin) order.push_back(index);
  }
  std::sort(order.begin(), order.end());
  ConsistencyFigure figure;
  std::vector<double> errors, standard_errors;
  std::vector<double> channel_errors[3];
  for (const int index : order) {
    BinPairs& pairs = by_bin[index];
    BinComparison bin;
    bin.center_deg = bins.CenterDeg(index);
    bin.count_a = bin.count_b = int(pairs.a[0].size());
    for (int c = 0; c < 3; ++c) {
      const double median = PercentileInPlace(&pairs.signed_diff[c], 0.5);
      bin.rel_error[c] = std::abs(median);
      bin.rel_error_se[c] = MedianStandardError(pairs.signed_diff[c], median);
      bin.value_a[c] = PercentileInPlace(&pairs.a[c], 0.5);
      bin.value_b[c] = PercentileInPlace(&pairs.b[c], 0.5);
      channel_errors[c].push_back(bin.rel_error[c]);
    }
    bin.mean_rel_error = bin.rel_error.mean();
    bin.mean_rel_error_se = bin.rel_error_se.mean();
    errors.push_back(bin.mean_rel_error);
    standard_errors.push_back(bin.mean_rel_error_se);
    figure.pairs += bin.count_a;
    figure.fitted_pairs += pairs.fitted;
    figure.bins.push_back(bin);
  }
  if (figure.valid()) {
    figure.median_rel_error = figure.overall_rel_error = Percentile(errors, 0.5);
    figure.p95_rel_error = Percentile(errors, 0.95);
    figure.median_bin_se = Percentile(standard_errors, 0.5);
    for (int c = 0; c < 3; ++c) figure.per_channel_rel_error[c] = Percentile(channel_errors[c], 0.5);
    std::vector<size_t> worst(figure.bins.size());
    for (size_t i = 0; i < worst.size(); ++i) worst[i] = i;
    std::stable_sort(worst.begin(), worst.end(), [&](size_t x, size_t y) { return errors[x] > errors[y]; });
    worst.resize(std::min<size_t>(worst.size(), size_t(options.worst_bins)));
    figure.worst = worst;
  }
  return figure;
}

nlohmann::json Rgb(const Eigen::Vector3d& v) { return {v[0], v[1], v[2]}; }

nlohmann::json BinJson(const BinComparison& bin) {
  return {{"theta_i_deg", bin.center_deg[0]},
          {"theta_e_deg", bin.center_deg[1]},
          {"delta_phi_deg", bin.center_deg[2]},
          {"pairs", bin.count_a},
          {"count_a", bin.count_a},
          {"count_b", bin.count_b},
          {"value_a", Rgb(bin.value_a)},
          {"value_b", Rgb(bin.value_b)},
          {"rel_error_rgb", Rgb(bin.rel_error)},
          {"rel_error", bin.mean_rel_error},
          {"rel_error_se_rgb", Rgb(bin.rel_error_se)},
          {"rel_error_se", bin.mean_rel_error_se}};
}

nlohmann::json FigureJson(const ConsistencyFigure& figure, int min_pairs) {
  nlohmann::json bins = nlohmann::json::array(), worst = nlohmann::json::array();
  for (const BinComparison& bin : figure.bins) bins.push_back(BinJson(bin));
  for (const size_t i : figure.worst) worst.push_back(BinJson(figure.bins[i]));
  return {{"valid", figure.valid()},
          {"headline", figure.Headline(min_pairs)},
          {"bins_compared", figure.bins.size()},
          {"pairs", figure.pairs},
          {"fitted_pairs", figure.fitted_pairs},
          {"overall_rel_error", figure.valid() ? nlohmann::json(figure.overall_rel_error) : nlohmann::json()},
          {"per_channel_rel_error", figure.valid() ? Rgb(figure.per_channel_rel_error) : nlohmann::json()},
          {"median_rel_error", figure.valid() ? nlohmann::json(figure.median_rel_error) : nlohmann::json()},
          {"p95_rel_error", figure.valid() ? nlohmann::json(figure.p95_rel_error) : nlohmann::json()},
          {"median_bin_se", figure.valid() ? nlohmann::json(figure.median_bin_se) : nlohmann::json()},
          {"worst_bins", worst},
          {"bins", bins}};
}

}  // namespace

std::string RegressionSummary(const PredictionReport& r) {
  auto figure = [](const char* name, const PairFigure& f) {
    char buffer[160];
    if (!f.valid()) {
      std::snprintf(buffer, sizeof(buffer), "%s invalid (no pair had two estimates)", name);
    } else {
      std::snprintf(buffer, sizeof(buffer), "%s median %.2f %%, p95 %.2f %% over %zu pairs", name, 100.0 * f.median,
                    100.0 * f.p95, f.pairs);
    }
    return std::string(buffer);
  };
  return "regression check: " + figure("reciprocity near the incidence plane", r.reciprocity) + "; " +
         figure("bilateral symmetry", r.bilateral) + "; " + HeldOutHeadline(r);
}

bool ConsistencyOptions::Check(std::string* why) const {
  if (!(theta_bin_deg > 0.0 && theta_bin_deg <= 45.0) || !(phi_bin_deg > 0.0 && phi_bin_deg <= 90.0)) {
    *why = "bin widths must be in (0, 45] degrees for theta and (0, 90] for delta_phi";
    return false;
  }
  if (std::abs(std::remainder(360.0, phi_bin_deg)) > 1e-9) {
    *why = "phi_bin_deg must divide 360, so that bins mirror onto bins";
    return false;
  }
  IBRDF_CHECK_OPTION_RANGE(min_samples_per_bin, 1, 1000000);
  IBRDF_CHECK_OPTION_RANGE(max_theta_deg, 1.0, 90.0);
  IBRDF_CHECK_OPTION(match_deg == 0.0 || (match_deg >= 0.01 && match_deg <= 5.0));
  IBRDF_CHECK_OPTION_RANGE(worst_bins, 0, 100);
  return true;
}

std::string ConsistencyFigure::Headline(int min_pairs) const {
  char buffer[256];
  if (!valid()) {
    std::snprintf(buffer, sizeof(buffer), "invalid: no bin had %d sample pairs", min_pairs);
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer), "%.2f %% median, %.2f %% p95 over %zu bins", 100.0 * median_rel_error,
                100.0 * p95_rel_error, bins.size());
  std::string line = buffer;
  if (!worst.empty()) {
    const BinComparison& w = bins[worst.front()];
    std::snprintf(buffer, sizeof(buffer), " (worst %.2f %% at theta_i %.0f, theta_e %.0f, delta_phi %.0f deg)",
                  100.0 * w.mean_rel_error, w.center_deg[0], w.center_deg[1], w.center_deg[2]);
    line += buffer;
  }
  return line;
}

ConsistencyReport CheckConsistency(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("check options", why);
  BinGrid bins;
  bins.theta_step = options.theta_bin_deg * kDegree;
  bins.phi_step = options.phi_bin_deg * kDegree;
  bins.n_theta = static_cast<int>(std::ceil(90.0 / options.theta_bin_deg - 1e-9));
  bins.n_phi = static_cast<int>(std::lround(360.0 / options.phi_bin_deg));

  // Usable: finite angles and values, both directions up to max_theta.
  const double max_theta = options.max_theta_deg * kDegree;
  std::vector<uint32_t> usable;
  for (size_t i = 0; i < samples.size(); ++i) {
    const BrdfSample& s = samples[i];
    if (!(std::isfinite(s.theta_i) && std::isfinite(s.theta_e) && std::isfinite(s.delta_phi))) continue;
    if (!(s.theta_i >= 0.0f && s.theta_i <= max_theta && s.theta_e >= 0.0f && s.theta_e <= max_theta)) continue;
    if (!(std::isfinite(s.brdf[0]) && std::isfinite(s.brdf[1]) && std::isfinite(s.brdf[2]))) continue;
    if (!s.AllValid()) continue;  // a channel not measured (clipped, below the floor): no pair figure
    usable.push_back(uint32_t(i));
  }
  ConsistencyReport report;
  report.samples = samples.size();
  report.min_pairs = options.min_samples_per_bin;
  const std::vector<double> radii =
      options.match_deg > 0.0 ? std::vector<double>{options.match_deg} : std::vector<double>{0.5, 1.0, 2.0, 4.0};
  for (const double radius : radii) {
    ConsistencyOptions at = options;
    at.match_deg = radius;
    const SampleGrid grid(samples, usable, radius * kDegree);
    report.match_deg = radius;
    // Each unordered pair once: reciprocity from the side theta_i < theta_e, bilateral symmetry from
    // delta_phi < 0. The two figures only read the grid: side by side on two threads.
    tbb::parallel_invoke(
        [&] {
          report.reciprocity = PairedFigure(samples, usable, grid, bins, at, Symmetry::kReciprocity,
                                            [](const BrdfSample& s) { return s.theta_i < s.theta_e; });
        },
        [&] {
          report.bilateral_symmetry = PairedFigure(samples, usable, grid, bins, at, Symmetry::kBilateral,
                                                   [](const BrdfSample& s) { return s.delta_phi < 0.0f; });
        });
    if (report.reciprocity.bins.size() >= ConsistencyReport::kAutoMinBins &&
        report.bilateral_symmetry.bins.size() >= ConsistencyReport::kAutoMinBins) {
      break;
    }
  }
  report.success = true;
  return report;
}

std::string ConsistencyReport::BriefReport() const {
  char radius[64];
  std::snprintf(radius, sizeof(radius), " (partners within %g deg)", match_deg);
  return "check: " + std::to_string(samples) + " samples" + radius + "; reciprocity " +
         reciprocity.Headline(min_pairs) + "; bilateral symmetry " + bilateral_symmetry.Headline(min_pairs);
}

nlohmann::json ToJson(const ConsistencyReport& report, const ConsistencyOptions& options) {
  const nlohmann::json bilateral = FigureJson(report.bilateral_symmetry, report.min_pairs);
  return {{"format", "ibrdf-consistency"},
          {"version", 2},
          {"samples", report.samples},
          {"method",
           "each sample (side A, at p) against the measured samples within match_deg of its reciprocal "
           "(mirrored) point q (side B), where their centroid lies within match_deg / 4 of q (no extrapolation): "
           "one least-squares fit of log f, quadratic in the offset from q, over side B as measured and side A's "
           "samples within match_deg of p taken to their images, plus side A's offset delta (slope and curvature "
           "shared, so they cancel); pairs whose delta has more than twice one sample's variance are dropped; "
           "with fewer than 11 samples around q (22 on both sides), the plain mean of side B at match_deg <= 1, "
           "else no pair; "
           "signed relative difference (a - b) / ((a + b) / 2) per pair (2 tanh(delta / 2) if fitted); a bin of "
           "(theta_i, theta_e, delta_phi) reports |median of its pairs' differences| and that median's standard "
           "error (rel_error_se); overall_rel_error = median over bins, p95_rel_error = 95th percentile over "
           "bins, median_bin_se = median over bins of rel_error_se"},
          {"options",
           {{"theta_bin_deg", options.theta_bin_deg},
            {"phi_bin_deg", options.phi_bin_deg},
            {"min_samples_per_bin", options.min_samples_per_bin},
            {"max_theta_deg", options.max_theta_deg},
            {"match_deg", options.match_deg}}},
          {"match_deg_used", report.match_deg},
          {"reciprocity", FigureJson(report.reciprocity, report.min_pairs)},
          {"bilateral_symmetry", bilateral},
          {"isotropy", bilateral},  // the old name, kept for one release
          {"aliases", {{"isotropy", "bilateral_symmetry (deprecated name, removed in the next release)"}}}};
}

nlohmann::json CheckSamples(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options,
                            const PredictionCheckOptions* prediction, ConsistencyReport* report_out) {
  const ConsistencyReport report = CheckConsistency(samples, options);
  nlohmann::json json = ToJson(report, options);
  if (prediction) {
    const PredictionReport predicted = CheckWithRegression(samples, *prediction);
    json["regression"] = ToJson(predicted, *prediction);
    Log(1, RegressionSummary(predicted));
  }
  Log(1, report.BriefReport());
  if (report_out) *report_out = report;
  return json;
}

}  // namespace ibrdf
