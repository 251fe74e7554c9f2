#include "reconstruct/consistency.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "reconstruct/prediction_check.h"

namespace ibrdf {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct BinGrid {
  int n_theta = 0, n_phi = 0;
  double theta_step = 0, phi_step = 0;  // radians

  int Index(int i, int j, int k) const { return (i * n_theta + j) * n_phi + k; }
  Eigen::Vector3d Center(int i, int j, int k) const {
    return {(i + 0.5) * theta_step, (j + 0.5) * theta_step, -M_PI + (k + 0.5) * phi_step};
  }
};

// Local linear estimate of the BRDF at `center` from the samples of one bin. Coordinates are centred on
// the bin and scaled to bin widths, so the fit is well scaled; a complete orthogonal decomposition gives
// the minimum-norm slope where the samples span fewer than three dimensions.
Eigen::Vector3d EstimateAtCenter(const std::vector<const BrdfSample*>& members, const Eigen::Vector3d& center,
                                 const BinGrid& grid) {
  const int n = static_cast<int>(members.size());
  Eigen::MatrixXd design(n, 4);
  Eigen::MatrixXd values(n, 3);
  for (int r = 0; r < n; ++r) {
    const BrdfSample& s = *members[r];
    design(r, 0) = 1.0;
    design(r, 1) = (s.theta_i - center[0]) / grid.theta_step;
    design(r, 2) = (s.theta_e - center[1]) / grid.theta_step;
    design(r, 3) = (s.delta_phi - center[2]) / grid.phi_step;
    for (int c = 0; c < 3; ++c) values(r, c) = s.brdf[c];
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver(design);
  solver.setThreshold(1e-6);
  const Eigen::MatrixXd coefficients = solver.solve(values);
  Eigen::Vector3d estimate = coefficients.row(0).transpose();
  // A local linear fit can extrapolate across an empty half of the bin; fall back to the mean there.
  if (!estimate.allFinite() || (estimate.array() <= 0.0).any()) estimate = values.colwise().mean().transpose();
  return estimate;
}

void Summarize(ConsistencyFigure* figure) {
  double weight_sum = 0.0;
  std::vector<double> errors;
  for (const BinComparison& bin : figure->bins) {
    const double w = std::min(bin.count_a, bin.count_b);
    weight_sum += w;
    figure->overall_rel_error += w * bin.mean_rel_error;
    figure->per_channel_rel_error += w * bin.rel_error;
    errors.push_back(bin.mean_rel_error);
  }
  if (weight_sum > 0.0) {
    figure->overall_rel_error /= weight_sum;
    figure->per_channel_rel_error /= weight_sum;
  }
  figure->median_rel_error = Percentile(errors, 0.5);
  figure->p95_rel_error = Percentile(errors, 0.95);
}

nlohmann::json FigureJson(const ConsistencyFigure& figure) {
  nlohmann::json bins = nlohmann::json::array();
  for (const BinComparison& bin : figure.bins) {
    bins.push_back({{"theta_i_deg", bin.center_deg[0]},
                    {"theta_e_deg", bin.center_deg[1]},
                    {"delta_phi_deg", bin.center_deg[2]},
                    {"count_a", bin.count_a},
                    {"count_b", bin.count_b},
                    {"value_a", {bin.value_a[0], bin.value_a[1], bin.value_a[2]}},
                    {"value_b", {bin.value_b[0], bin.value_b[1], bin.value_b[2]}},
                    {"rel_error", bin.mean_rel_error}});
  }
  return {{"valid", figure.valid()},
          {"bins_compared", figure.bins.size()},
          {"overall_rel_error", figure.overall_rel_error},
          {"per_channel_rel_error",
           {figure.per_channel_rel_error[0], figure.per_channel_rel_error[1], figure.per_channel_rel_error[2]}},
          {"median_rel_error", figure.median_rel_error},
          {"p95_rel_error", figure.p95_rel_error},
          {"bins", bins}};
}

}  // namespace

bool ConsistencyOptions::Check(std::string* why) const {
  if (!(theta_bin_deg > 0.0 && theta_bin_deg <= 45.0) || !(phi_bin_deg > 0.0 && phi_bin_deg <= 90.0)) {
    *why = "bin widths must be in (0, 45] degrees for theta and (0, 90] for delta_phi";
    return false;
  }
  if (std::abs(std::remainder(360.0, phi_bin_deg)) > 1e-9) {
    *why = "phi_bin_deg must divide 360, so that bins mirror onto bins";
    return false;
  }
  if (min_samples_per_bin < 4) {
    *why = "min_samples_per_bin must be at least 4 (a local linear fit has 4 unknowns)";
    return false;
  }
  return true;
}

ConsistencyReport CheckConsistency(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("check options", why);
  BinGrid grid;
  grid.theta_step = options.theta_bin_deg * kDegree;
  grid.phi_step = options.phi_bin_deg * kDegree;
  grid.n_theta = static_cast<int>(std::ceil(90.0 / options.theta_bin_deg - 1e-9));
  grid.n_phi = static_cast<int>(std::lround(360.0 / options.phi_bin_deg));

  std::unordered_map<int, std::vector<const BrdfSample*>> bins;
  for (const BrdfSample& s : samples) {
    if (!std::isfinite(s.theta_i) || !std::isfinite(s.theta_e) || !std::isfinite(s.delta_phi)) continue;
    // Clamped before the cast: a float beyond int's range is undefined behaviour (UBSan, issue 17).
    const int i = static_cast<int>(std::clamp(s.theta_i / grid.theta_step, -1.0, grid.n_theta - 1.0));
    const int j = static_cast<int>(std::clamp(s.theta_e / grid.theta_step, -1.0, grid.n_theta - 1.0));
    const int k = static_cast<int>(std::clamp((s.delta_phi + M_PI) / grid.phi_step, 0.0, grid.n_phi - 1.0));
    if (i < 0 || j < 0) continue;
    bins[grid.Index(i, j, k)].push_back(&s);
  }
  const int n_limit = static_cast<int>(std::floor(options.max_theta_deg / options.theta_bin_deg + 1e-9));

  std::unordered_map<int, Eigen::Vector3d> estimates;
  auto estimate = [&](int i, int j, int k) {
    const int index = grid.Index(i, j, k);
    auto it = estimates.find(index);
    if (it == estimates.end()) {
      it = estimates.emplace(index, EstimateAtCenter(bins[index], grid.Center(i, j, k), grid)).first;
    }
    return it->second;
  };
  auto compare = [&](int i, int j, int k, int i2, int j2, int k2, ConsistencyFigure* figure) {
    const auto a = bins.find(grid.Index(i, j, k));
    const auto b = bins.find(grid.Index(i2, j2, k2));
    if (a == bins.end() || b == bins.end()) return;
    if (static_cast<int>(a->second.size()) < options.min_samples_per_bin ||
        static_cast<int>(b->second.size()) < options.min_samples_per_bin) {
      return;
    }
    BinComparison bin;
    bin.center_deg = grid.Center(i, j, k) / kDegree;
    bin.count_a = static_cast<int>(a->second.size());
    bin.count_b = static_cast<int>(b->second.size());
    bin.value_a = estimate(i, j, k);
    bin.value_b = estimate(i2, j2, k2);
    for (int c = 0; c < 3; ++c) {
      const double mean = 0.5 * (bin.value_a[c] + bin.value_b[c]);
      bin.rel_error[c] = mean > 0.0 ? std::abs(bin.value_a[c] - bin.value_b[c]) / mean : 0.0;
    }
    bin.mean_rel_error = bin.rel_error.mean();
    figure->bins.push_back(bin);
  };

  ConsistencyReport report;
  report.samples = samples.size();
  for (int i = 0; i < n_limit; ++i) {
    for (int j = 0; j < n_limit; ++j) {
      for (int k = 0; k < grid.n_phi; ++k) {
        const int mirrored = grid.n_phi - 1 - k;  // the bin of -delta_phi
        // Each unordered pair once: reciprocity below the diagonal, isotropy on the negative side.
        if (i < j) compare(i, j, k, j, i, mirrored, &report.reciprocity);
        if (k < mirrored) compare(i, j, k, i, j, mirrored, &report.isotropy);
      }
    }
  }
  Summarize(&report.reciprocity);
  Summarize(&report.isotropy);
  report.success = true;
  return report;
}

std::string ConsistencyReport::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "check: %zu samples; reciprocity %.2f %% over %zu bin pairs; isotropy %.2f %% over %zu bin pairs",
                samples, 100.0 * reciprocity.overall_rel_error, reciprocity.bins.size(),
                100.0 * isotropy.overall_rel_error, isotropy.bins.size());
  return buffer;
}

nlohmann::json ToJson(const ConsistencyReport& report, const ConsistencyOptions& options) {
  return {{"format", "ibrdf-consistency"},
          {"version", 1},
          {"samples", report.samples},
          {"method",
           "binned in (theta_i, theta_e, delta_phi); each bin's value estimated at its centre by a local "
           "linear fit; pairs compared as |a - b| / ((a + b) / 2); overall = mean over pairs weighted by "
           "the smaller sample count"},
          {"options",
           {{"theta_bin_deg", options.theta_bin_deg},
            {"phi_bin_deg", options.phi_bin_deg},
            {"min_samples_per_bin", options.min_samples_per_bin},
            {"max_theta_deg", options.max_theta_deg}}},
          {"reciprocity", FigureJson(report.reciprocity)},
          {"isotropy", FigureJson(report.isotropy)}};
}

nlohmann::json CheckSamples(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options,
                            const PredictionCheckOptions* prediction, ConsistencyReport* report_out) {
  const ConsistencyReport report = CheckConsistency(samples, options);
  nlohmann::json json = ToJson(report, options);
  if (prediction) {
    const PredictionReport predicted = CheckWithRegression(samples, *prediction);
    json["regression"] = ToJson(predicted, *prediction);
    Log(1, predicted.BriefReport());
  }
  Log(1, report.BriefReport());
  if (!report.reciprocity.valid()) Log(1, "warning: no bin pair had enough samples for a reciprocity figure");
  if (!report.isotropy.valid()) Log(1, "warning: no bin pair had enough samples for an isotropy figure");
  if (report_out) *report_out = report;
  return json;
}

}  // namespace ibrdf
