#include "reconstruct/consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
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

// The samples in a grid of cells `cell` radians wide, for nearest-partner queries: the usable samples
// sorted by cell (x, y, z) and index, so a column of cells (x, y) is one run of the arrays, found by a
// dense (x, y) table, and its cells z - 1 .. z + 1 one stretch of it.
class PartnerGrid {
 public:
  PartnerGrid(const std::vector<BrdfSample>& samples, const std::vector<uint32_t>& usable, double cell) : cell_(cell) {
    const size_t n = usable.size();
    std::vector<Eigen::Vector3i> cells(n);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
      const BrdfSample& s = samples[usable[i]];
      cells[i] = Cell(Embed(s.theta_i, s.theta_e, s.delta_phi));
    });
    if (n == 0) return;
    lo_ = hi_ = cells[0].head<2>();
    for (const Eigen::Vector3i& c : cells) {
      lo_ = lo_.cwiseMin(c.head<2>());
      hi_ = hi_.cwiseMax(c.head<2>());
    }
    size_x_ = hi_.x() - lo_.x() + 1;
    size_y_ = hi_.y() - lo_.y() + 1;
    // Sorted by (x, y, z), then by sample index: within a cell the samples keep their file order, so a
    // partner's sum adds them in the order of the hash grid before (the same bits).
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
      const Eigen::Vector3i &ca = cells[a], &cb = cells[b];
      if (ca.x() != cb.x()) return ca.x() < cb.x();
      if (ca.y() != cb.y()) return ca.y() < cb.y();
      if (ca.z() != cb.z()) return ca.z() < cb.z();
      return a < b;
    });
    index_.resize(n);
    z_.resize(n);
    points_.resize(n);
    values_.resize(n);
    tbb::parallel_for(size_t(0), n, [&](size_t k) {
      const uint32_t index = usable[order[k]];
      const BrdfSample& s = samples[index];
      index_[k] = index;
      z_[k] = cells[order[k]].z();
      points_[k] = Embed(s.theta_i, s.theta_e, s.delta_phi);
      values_[k] = Eigen::Vector3f(s.brdf[0], s.brdf[1], s.brdf[2]);
    });
    columns_.assign(size_t(size_x_) * size_y_ + 1, 0);
    for (size_t k = 0; k < n; ++k) ++columns_[Column(cells[order[k]]) + 1];
    for (size_t c = 1; c < columns_.size(); ++c) columns_[c] += columns_[c - 1];
  }

  // The partner of `target`: the samples within `radius` (<= the cell size) whose centroid lies within
  // `radius` * kMaxCentroidOffset of it, so that the target is surrounded by them (interpolation, not
  // extrapolation: the BRDF's slope cancels to first order in their mean). Returns false otherwise, or
  // when `exclude` is among them only.
  bool Partner(const Eigen::Vector3d& target, double radius, uint32_t exclude, Eigen::Vector3d* value) const {
    constexpr double kMaxCentroidOffset = 0.25;
    const Eigen::Vector3i c = Cell(target);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (int x = c.x() - 1; x <= c.x() + 1; ++x) {
      if (x < lo_.x() || x > hi_.x()) continue;
      for (int y = c.y() - 1; y <= c.y() + 1; ++y) {
        if (y < lo_.y() || y > hi_.y()) continue;
        const size_t column = Column(Eigen::Vector3i(x, y, 0));
        const auto begin = z_.begin() + columns_[column], end = z_.begin() + columns_[column + 1];
        for (auto it = std::lower_bound(begin, end, c.z() - 1); it != end && *it <= c.z() + 1; ++it) {
          const size_t k = size_t(it - z_.begin());
          if (index_[k] == exclude || (points_[k] - target).squaredNorm() > radius * radius) continue;
          centroid += points_[k];
          sum += values_[k].cast<double>();
          ++n;
        }
      }
    }
    if (n == 0 || (centroid / n - target).norm() > kMaxCentroidOffset * radius) return false;
    *value = sum / n;
    return true;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    // The embedding is bounded by pi/2 in every coordinate, so the cells fit an int.
    return {int(std::floor(p[0] / cell_)), int(std::floor(p[1] / cell_)), int(std::floor(p[2] / cell_))};
  }
  size_t Column(const Eigen::Vector3i& c) const { return size_t(c.x() - lo_.x()) * size_y_ + (c.y() - lo_.y()); }

  double cell_;
  Eigen::Vector2i lo_ = Eigen::Vector2i::Zero(), hi_ = Eigen::Vector2i::Constant(-1);  // (x, y) cells held
  int size_x_ = 0, size_y_ = 0;
  std::vector<size_t> columns_;          // column (x, y) holds entries [columns_[c], columns_[c + 1])
  std::vector<uint32_t> index_;          // sample index of each entry
  std::vector<int> z_;                   // z cell of each entry (increasing within a column)
  std::vector<Eigen::Vector3d> points_;  // embedded point of each entry
  std::vector<Eigen::Vector3f> values_;  // brdf of each entry
};

// The pairs of one bin: signed relative differences and both values, per channel.
struct BinPairs {
  std::vector<double> signed_diff[3], a[3], b[3];
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

// Bins the pairs of every sample that `take` selects with its partner near `partner_point(sample)`.
template <typename Take, typename PartnerPoint>
ConsistencyFigure PairedFigure(const std::vector<BrdfSample>& samples, const std::vector<uint32_t>& usable,
                               const PartnerGrid& grid, const BinGrid& bins, const ConsistencyOptions& options,
                               Take take, PartnerPoint partner_point) {
  std::unordered_map<int, BinPairs> by_bin;
  const double radius = options.match_deg * kDegree;
  // The partner searches in parallel, a block at a time into a reused buffer; the pairs are then added
  // to their bins serially in sample order (the same bins, in the same order, as the one-thread loop).
  constexpr size_t kBlock = 1 << 16;
  struct Found {
    bool paired = false;
    Eigen::Vector3d b;
  };
  std::vector<Found> block(std::min(kBlock, usable.size()));
  for (size_t begin = 0; begin < usable.size(); begin += kBlock) {
    const size_t end = std::min(usable.size(), begin + kBlock);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 512), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) {
        const uint32_t index = usable[i];
        const BrdfSample& a = samples[index];
        Found& found = block[i - begin];
        found.paired = take(a) && grid.Partner(partner_point(a), radius, index, &found.b);
      }
    });
    for (size_t i = begin; i < end; ++i) {
      const Found& found = block[i - begin];
      if (!found.paired) continue;
      const BrdfSample& a = samples[usable[i]];
      const Eigen::Vector3d& b = found.b;
      BinPairs& pairs = by_bin[bins.Index(a)];
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
  std::vector<double> errors;
  std::vector<double> channel_errors[3];
  for (const int index : order) {
    BinPairs& pairs = by_bin[index];
    BinComparison bin;
    bin.center_deg = bins.CenterDeg(index);
    bin.count_a = bin.count_b = int(pairs.a[0].size());
    for (int c = 0; c < 3; ++c) {
      bin.rel_error[c] = std::abs(PercentileInPlace(&pairs.signed_diff[c], 0.5));
      bin.value_a[c] = PercentileInPlace(&pairs.a[c], 0.5);
      bin.value_b[c] = PercentileInPlace(&pairs.b[c], 0.5);
      channel_errors[c].push_back(bin.rel_error[c]);
    }
    bin.mean_rel_error = bin.rel_error.mean();
    errors.push_back(bin.mean_rel_error);
    figure.pairs += bin.count_a;
    figure.bins.push_back(bin);
  }
  if (figure.valid()) {
    figure.median_rel_error = figure.overall_rel_error = Percentile(errors, 0.5);
    figure.p95_rel_error = Percentile(errors, 0.95);
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
          {"rel_error", bin.mean_rel_error}};
}

nlohmann::json FigureJson(const ConsistencyFigure& figure, int min_pairs) {
  nlohmann::json bins = nlohmann::json::array(), worst = nlohmann::json::array();
  for (const BinComparison& bin : figure.bins) bins.push_back(BinJson(bin));
  for (const size_t i : figure.worst) worst.push_back(BinJson(figure.bins[i]));
  return {{"valid", figure.valid()},
          {"headline", figure.Headline(min_pairs)},
          {"bins_compared", figure.bins.size()},
          {"pairs", figure.pairs},
          {"overall_rel_error", figure.valid() ? nlohmann::json(figure.overall_rel_error) : nlohmann::json()},
          {"per_channel_rel_error", figure.valid() ? Rgb(figure.per_channel_rel_error) : nlohmann::json()},
          {"median_rel_error", figure.valid() ? nlohmann::json(figure.median_rel_error) : nlohmann::json()},
          {"p95_rel_error", figure.valid() ? nlohmann::json(figure.p95_rel_error) : nlohmann::json()},
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
    const PartnerGrid grid(samples, usable, radius * kDegree);
    report.match_deg = radius;
    // Each unordered pair once: reciprocity from the side theta_i < theta_e, bilateral symmetry from
    // delta_phi < 0. The two figures only read the grid: side by side on two threads.
    tbb::parallel_invoke(
        [&] {
          report.reciprocity = PairedFigure(
              samples, usable, grid, bins, at, [](const BrdfSample& s) { return s.theta_i < s.theta_e; },
              [](const BrdfSample& s) { return Embed(s.theta_e, s.theta_i, -s.delta_phi); });
        },
        [&] {
          report.bilateral_symmetry = PairedFigure(
              samples, usable, grid, bins, at, [](const BrdfSample& s) { return s.delta_phi < 0.0f; },
              [](const BrdfSample& s) { return Embed(s.theta_i, s.theta_e, -s.delta_phi); });
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
           "each sample paired with the mean of the measured samples within match_deg of its reciprocal "
           "(mirrored) point, where their centroid lies within match_deg / 4 of it (no extrapolation); signed relative "
           "difference (a - b) / ((a + b) / 2) per "
           "pair; a bin of (theta_i, theta_e, delta_phi) reports |median of its pairs' differences|; "
           "overall_rel_error = median over bins, p95_rel_error = 95th percentile over bins"},
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
