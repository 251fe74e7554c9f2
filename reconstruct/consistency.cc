#include "reconstruct/consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

#include <tbb/parallel_invoke.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "reconstruct/prediction_check.h"

namespace ibrdf {
namespace {

constexpr double kDegree = M_PI / 180.0;

// A point of the isotropic domain embedded so that distances are angles: (theta_i, theta_e cos dphi,
// theta_e sin dphi), radians (the exitant direction's azimuthal-equidistant projection in the frame where
// the light has azimuth 0).
Eigen::Vector3d Embed(double theta_i, double theta_e, double delta_phi) {
  return {theta_i, theta_e * std::cos(delta_phi), theta_e * std::sin(delta_phi)};
}

// The samples in a hash grid of cells `cell` radians wide, for nearest-partner queries.
class PartnerGrid {
 public:
  PartnerGrid(const std::vector<BrdfSample>& samples, const std::vector<uint32_t>& usable, double cell)
      : samples_(samples), cell_(cell) {
    points_.resize(samples.size());
    for (const uint32_t index : usable) {
      const BrdfSample& s = samples[index];
      points_[index] = Embed(s.theta_i, s.theta_e, s.delta_phi);
      cells_[Key(Cell(points_[index]))].push_back(index);
    }
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
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const uint32_t index : it->second) {
            if (index == exclude || (points_[index] - target).squaredNorm() > radius * radius) continue;
            centroid += points_[index];
            const BrdfSample& s = samples_[index];
            sum += Eigen::Vector3d(s.brdf[0], s.brdf[1], s.brdf[2]);
            ++n;
          }
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
  static int64_t Key(const Eigen::Vector3i& c) {
    return ((int64_t(c[0]) + 4096) << 26) | ((int64_t(c[1]) + 4096) << 13) | (int64_t(c[2]) + 4096);
  }

  const std::vector<BrdfSample>& samples_;
  double cell_;
  std::vector<Eigen::Vector3d> points_;
  std::unordered_map<int64_t, std::vector<uint32_t>> cells_;
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
  for (const uint32_t index : usable) {
    const BrdfSample& a = samples[index];
    if (!take(a)) continue;
    Eigen::Vector3d b;
    if (!grid.Partner(partner_point(a), radius, index, &b)) continue;
    BinPairs& pairs = by_bin[bins.Index(a)];
    for (int c = 0; c < 3; ++c) {
      const double mean = 0.5 * (double(a.brdf[c]) + b[c]);
      pairs.signed_diff[c].push_back(mean > 0.0 ? (double(a.brdf[c]) - b[c]) / mean : 0.0);
      pairs.a[c].push_back(a.brdf[c]);
      pairs.b[c].push_back(b[c]);
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
  char held[160];
  std::snprintf(held, sizeof(held), "%zu held-out photos, RMS prediction error R G B %.2f %.2f %.2f %%",
                r.held_out.size(), 100.0 * r.held_out_rms[0], 100.0 * r.held_out_rms[1], 100.0 * r.held_out_rms[2]);
  return "regression check: " + figure("reciprocity near the incidence plane", r.reciprocity) + "; " +
         figure("bilateral symmetry", r.bilateral) + "; " + (r.held_out.empty() ? "no held-out photos" : held);
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
