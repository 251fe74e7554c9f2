#include "spatial/material_weights.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include "core/error.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "spatial/uniformity.h"

namespace ibrdf {
namespace {

// The non-negative weights minimising |A w - b|^2. Few bases (at most kMaxBases) make the exact answer
// cheap: the optimum is the unconstrained least squares on some subset of the bases, so every subset's
// normal equations are solved and the feasible one of least cost kept. (Ceres' bounded trust region
// stalled 1 % short of the optimum at an active bound in MaterialWeights.WeightsStayNonNegative, and
// Eigen 3.4 has no NNLS.)
Eigen::VectorXd NonNegativeLeastSquares(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const int n = int(a.cols());
  const Eigen::MatrixXd ata = a.transpose() * a;
  const Eigen::VectorXd atb = a.transpose() * b;
  Eigen::VectorXd best = Eigen::VectorXd::Zero(n);
  double best_cost = 0.0;  // of w = 0, relative to |b|^2: |A w - b|^2 - |b|^2 = w'A'A w - 2 w'A'b
  for (unsigned subset = 1; subset < (1u << n); ++subset) {
    std::vector<int> free;
    for (int g = 0; g < n; ++g) {
      if (subset & (1u << g)) free.push_back(g);
    }
    const int m = int(free.size());
    Eigen::MatrixXd sub(m, m);
    Eigen::VectorXd rhs(m);
    for (int i = 0; i < m; ++i) {
      rhs[i] = atb[free[i]];
      for (int j = 0; j < m; ++j) sub(i, j) = ata(free[i], free[j]);
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(sub);
    if (ldlt.info() != Eigen::Success) continue;
    const Eigen::VectorXd x = ldlt.solve(rhs);
    if (!x.allFinite() || (x.array() < 0.0).any()) continue;
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < m; ++i) w[free[i]] = x[i];
    const double cost = w.dot(ata * w) - 2.0 * w.dot(atb);
    if (cost < best_cost) {
      best_cost = cost;
      best = w;
    }
  }
  return best;
}

void FitCell(const LocatedSample* begin, const LocatedSample* end, const std::vector<const BrdfModel*>& bases,
             const MaterialWeightsOptions& options, CellWeights* cell) {
  const int n_bases = int(bases.size());
  cell->key = begin->key;
  cell->samples = uint32_t(end - begin);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  // One row per usable sample channel: the bases' values and the sample's, each over the bases' mean.
  std::vector<double> basis_values, values;
  std::vector<int> channel;
  int per_channel[3] = {0, 0, 0};
  std::vector<Eigen::Vector3d> f(n_bases);
  for (const LocatedSample* s = begin; s != end; ++s) {
    sum += s->point.cast<double>();
    const BrdfSample& b = s->sample;
    const Eigen::Vector3d wi(b.wi[0], b.wi[1], b.wi[2]), wo(b.wo[0], b.wo[1], b.wo[2]);
    for (int g = 0; g < n_bases; ++g) f[g] = bases[g]->Eval(wi, wo);
    for (int k = 0; k < 3; ++k) {
      if (!b.Valid(k) || !std::isfinite(b.brdf[k])) continue;
      double mean = 0.0;
      bool usable = true;
      for (int g = 0; g < n_bases; ++g) {
        usable = usable && f[g][k] > 0.0 && std::isfinite(f[g][k]);
        mean += f[g][k] / n_bases;
      }
      if (!usable) continue;
      for (int g = 0; g < n_bases; ++g) basis_values.push_back(f[g][k] / mean);
      values.push_back(b.brdf[k] / mean);
      channel.push_back(k);
      ++per_channel[k];
    }
  }
  cell->centre = sum / double(cell->samples);
  cell->usable = uint32_t(values.size());
  if (*std::max_element(per_channel, per_channel + 3) < options.min_cell_samples) return;
  const Eigen::Index n_rows = Eigen::Index(values.size());
  const Eigen::MatrixXd a =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(basis_values.data(),
                                                                                                n_rows, n_bases);
  const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(values.data(), n_rows);
  cell->weights = NonNegativeLeastSquares(a, b);
  cell->fitted = true;
  Eigen::Index dominant = 0;
  cell->weights.maxCoeff(&dominant);
  cell->dominant = int(dominant);
  const Eigen::VectorXd fit = a * cell->weights;
  cell->rel_rms = std::sqrt((fit - b).squaredNorm() / double(n_rows));
  // Per channel: the median of sample / combination and its standard error, judged as the uniformity
  // check judges a cell (spatial/uniformity.h), against 1.
  cell->fits = true;
  for (int k = 0; k < 3; ++k) {
    if (per_channel[k] < options.min_cell_samples) continue;
    std::vector<float> ratios;
    for (Eigen::Index i = 0; i < n_rows; ++i) {
      if (channel[size_t(i)] == k && fit[i] > 0.0) ratios.push_back(float(b[i] / fit[i]));
    }
    if (ratios.size() < size_t(options.min_cell_samples)) {
      cell->fits = false;  // the combination is zero where the samples are not: nothing spans them
      continue;
    }
    MedianAndStandardError(&ratios, &cell->ratio[k], &cell->noise[k]);
    if (RatioDeviates(cell->ratio[k], 1.0, cell->noise[k], options.deviation, options.noise_sigmas)) cell->fits = false;
  }
}

}  // namespace

bool MaterialWeightsOptions::Check(std::string* why) const {
  if (min_cell_samples < 3) {
    *why = "a cell needs at least 3 samples to be fitted";
    return false;
  }
  return CheckDeviationBound(deviation, noise_sigmas, warn_fraction, fail_fraction, why);
}

MaterialWeightsResult ProjectOntoBases(std::vector<LocatedSample>* samples, const std::vector<const BrdfModel*>& bases,
                                       const MaterialWeightsOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("material weights options", why);
  if (bases.empty()) ThrowError("material weights", "no basis BRDF to project the cells onto");
  if (bases.size() > size_t(kMaxBases)) {
    ThrowError("material weights", std::to_string(bases.size()) + " bases: at most " + std::to_string(kMaxBases));
  }
  const auto start = std::chrono::steady_clock::now();
  std::sort(samples->begin(), samples->end(),
            [](const LocatedSample& a, const LocatedSample& b) { return a.key < b.key; });
  std::vector<size_t> begin;
  for (size_t i = 0; i < samples->size(); ++i) {
    if (i == 0 || (*samples)[i].key != (*samples)[i - 1].key) begin.push_back(i);
  }
  begin.push_back(samples->size());
  MaterialWeightsResult result;
  result.bases = bases.size();
  result.cells.resize(begin.size() - 1);
  const LocatedSample* data = samples->data();
  tbb::parallel_for(size_t(0), result.cells.size(), [&](size_t c) {
    FitCell(data + begin[c], data + begin[c + 1], bases, options, &result.cells[c]);
  });
  std::vector<double> residuals;
  for (const CellWeights& cell : result.cells) {
    if (!cell.fitted) continue;
    ++result.cells_fitted;
    if (!cell.fits) ++result.cells_not_fitting;
    residuals.push_back(cell.rel_rms);
  }
  if (result.cells_fitted > 0) {
    result.not_fitting_fraction = double(result.cells_not_fitting) / double(result.cells_fitted);
    result.median_rel_rms = Median(residuals);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string MaterialWeightsResult::BriefReport(const MaterialWeightsOptions& options) const {
  return "weights: " + std::to_string(cells_fitted) + " cells fitted over " + std::to_string(bases) +
         (bases == 1 ? " basis; " : " bases; ") + std::to_string(cells_not_fitting) + " (" +
         Fixed(100.0 * not_fitting_fraction, 1) + " %) fit no combination (beyond " +
         Fixed(1.0 + options.deviation, 2) + "x and " + Fixed(options.noise_sigmas, 0) +
         " sigma); median residual " + Fixed(100.0 * median_rel_rms, 1) + " %; " + Fixed(seconds, 1) + " s";
}

std::unordered_map<uint64_t, size_t> FittedCellsByKey(const MaterialWeightsResult& weights) {
  std::unordered_map<uint64_t, size_t> cell_of_key;
  for (size_t c = 0; c < weights.cells.size(); ++c) {
    if (weights.cells[c].fitted) cell_of_key.emplace(weights.cells[c].key, c);
  }
  return cell_of_key;
}

}  // namespace ibrdf
