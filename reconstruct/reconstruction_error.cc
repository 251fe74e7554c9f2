#include "reconstruct/reconstruction_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/statistics.h"

namespace ibrdf {
namespace {

struct Cell {
  HalfDiffAngles angles;
  Eigen::Vector3d wi, wo;
  size_t flat;
};

// Cell centres with both directions within the theta limit, in flat index order (theta_h rows
// TBB-parallel, then joined).
std::vector<Cell> Cells(double max_theta_deg, int stride) {
  const double cos_limit = std::cos(max_theta_deg * M_PI / 180.0);
  std::vector<std::vector<Cell>> rows((kMerlThetaH + stride - 1) / stride);
  tbb::parallel_for(size_t(0), rows.size(), [&](size_t row) {
    const int i = int(row) * stride;
    std::vector<Cell>& cells = rows[row];
    cells.reserve(size_t(kMerlThetaD) * kMerlPhiD);
    for (int j = 0; j < kMerlThetaD; j += stride) {
      for (int k = 0; k < kMerlPhiD; k += stride) {
        Cell cell;
        cell.angles = MerlCellCentre(i, j, k);
        FromHalfDiff(cell.angles, &cell.wi, &cell.wo);
        if (!(cell.wi.z() >= cos_limit && cell.wo.z() >= cos_limit)) continue;
        cell.flat = MerlFlatIndex(i, j, k);
        cells.push_back(cell);
      }
    }
  });
  size_t total = 0;
  for (const std::vector<Cell>& row : rows) total += row.size();
  std::vector<Cell> cells;
  cells.reserve(total);
  for (const std::vector<Cell>& row : rows) cells.insert(cells.end(), row.begin(), row.end());
  return cells;
}

constexpr int kThetaHBands = 9;
constexpr double kThetaHBandDeg = 10.0;

class Accumulator {
 public:
  Accumulator() {
    for (int b = 0; b < kThetaHBands; ++b) {
      ThetaHBandBias band;
      band.theta_h_min_deg = b * kThetaHBandDeg;
      band.theta_h_max_deg = (b + 1) * kThetaHBandDeg;
      error_.theta_h_bands.push_back(band);
    }
  }
  void Add(const Eigen::Vector3d& f, const Eigen::Vector3d& truth, double theta_h) {
    if (!(truth.array() > 0.0).all()) return;
    AddRelative((f - truth).cwiseQuotient(truth), Band(theta_h));
  }
  // The theta_h band of a cell.
  static int Band(double theta_h) {
    return std::clamp(static_cast<int>(theta_h * 180.0 / M_PI / kThetaHBandDeg), 0, kThetaHBands - 1);
  }
  // Add() with the relative error (f - truth) / truth and the band already computed.
  void AddRelative(const Eigen::Vector3d& rel, int band) {
    ++error_.theta_h_bands[band].points;
    error_.theta_h_bands[band].mean_rel += rel;
    sum_ += rel.cwiseAbs2();
    for (int c = 0; c < 3; ++c) abs_[c].push_back(std::abs(rel[c]));
    ++error_.points;
  }
  void Outside(size_t cells = 1) { error_.outside += cells; }
  // Room for `points` Add() calls (no reallocation while adding).
  void Reserve(size_t points) {
    for (std::vector<double>& values : abs_) values.reserve(points);
  }
  ReconstructionError Finish() {
    if (error_.points > 0) {
      error_.rel_rms = (sum_ / double(error_.points)).cwiseSqrt();
      error_.rel_rms_all = std::sqrt(sum_.sum() / (3.0 * error_.points));
      for (int c = 0; c < 3; ++c) {
        error_.median[c] = PercentileInPlace(&abs_[c], 0.5);
        error_.p95[c] = PercentileInPlace(&abs_[c], 0.95);
      }
    }
    for (ThetaHBandBias& band : error_.theta_h_bands) {
      if (band.points > 0) band.mean_rel /= double(band.points);
    }
    return error_;
  }

 private:
  ReconstructionError error_;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  std::vector<double> abs_[3];
};

}  // namespace

std::string ReconstructionError::Brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "relative RMS error R G B %.2f %.2f %.2f %% (all %.2f %%) over %zu cells (coverage %.1f %%)",
                100 * rel_rms[0], 100 * rel_rms[1], 100 * rel_rms[2], 100 * rel_rms_all, points, 100 * coverage());
  return buffer;
}

ReconstructionError CompareRegressionWithTruth(const LocalRegression& regression, const BrdfModel& truth,
                                               double max_theta_deg, int stride) {
  const std::vector<Cell> cells = Cells(max_theta_deg, std::max(1, stride));
  std::vector<Eigen::Vector3d> points;
  for (const Cell& cell : cells) points.push_back(RegressionCoordinates(cell.angles));
  const std::vector<Estimate> estimates = regression.EvaluateMany(points, nullptr);
  Accumulator accumulator;
  for (size_t i = 0; i < cells.size(); ++i) {
    const Estimate& e = estimates[i];
    if (!InMeasuredDomain(e)) {
      accumulator.Outside();
      continue;
    }
    accumulator.Add(e.value, truth.Eval(cells[i].wi, cells[i].wo), cells[i].angles.theta_h);
  }
  return accumulator.Finish();
}

ReconstructionError CompareTableWithTruth(const MerlTable& table, const BrdfModel& truth, double max_theta_deg,
                                          const std::vector<uint8_t>* measured_domain) {
  return CompareTableWithTruth(table, truth, max_theta_deg, std::vector<const std::vector<uint8_t>*>{measured_domain})
      .front();
}

std::vector<ReconstructionError> CompareTableWithTruth(const MerlTable& table, const BrdfModel& truth,
                                                       double max_theta_deg,
                                                       const std::vector<const std::vector<uint8_t>*>& domains) {
  for (const std::vector<uint8_t>* domain : domains) IBRDF_CHECK(!domain || domain->size() == kMerlCells);
  IBRDF_CHECK(domains.size() <= 8);
  // Per theta_h row (TBB-parallel): the cells within the theta limit, and for each one some comparison
  // scores, its relative error against the truth (the truth evaluated once for all comparisons), its
  // theta_h band and which comparisons score it. The sums below then run over the rows and cells in
  // flat index order, as one comparison alone would: the same bits as evaluating every cell's truth
  // into a table of cell records first, without that table's 200 MB (docs/decisions.md).
  struct Scored {
    Eigen::Vector3d rel;  // (f - f_true) / f_true; unset where the truth is not positive
    uint8_t domains = 0;  // bit d: comparison d scores the cell
    int8_t band = -1;     // theta_h band; -1: the truth is not positive (the cell is not counted)
  };
  struct Row {
    std::vector<Scored> cells;
    size_t within = 0;                  // cells within the theta limit
    std::array<size_t, 8> scored = {};  // per comparison: cells it scores
  };
  const double cos_limit = std::cos(max_theta_deg * M_PI / 180.0);
  std::vector<Row> rows(kMerlThetaH);
  tbb::parallel_for(0, kMerlThetaH, [&](int i) {
    Row& row = rows[i];
    row.cells.reserve(size_t(kMerlThetaD) * kMerlPhiD);  // address space only: pages are touched as written
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        const HalfDiffAngles angles = MerlCellCentre(i, j, k);
        Eigen::Vector3d wi, wo;
        FromHalfDiff(angles, &wi, &wo);
        if (!(wi.z() >= cos_limit && wo.z() >= cos_limit)) continue;
        ++row.within;
        const size_t flat = MerlFlatIndex(i, j, k);
        if (!table.Measured(flat)) continue;
        Scored cell;
        for (size_t d = 0; d < domains.size(); ++d) {
          if (!domains[d] || (*domains[d])[flat]) {
            cell.domains |= uint8_t(1u << d);
            ++row.scored[d];
          }
        }
        if (cell.domains == 0) continue;
        const Eigen::Vector3d truth_value = truth.Eval(wi, wo);
        if ((truth_value.array() > 0.0).all()) {
          cell.rel = (table.Cell(flat) - truth_value).cwiseQuotient(truth_value);
          cell.band = static_cast<int8_t>(Accumulator::Band(angles.theta_h));
        }
        row.cells.push_back(cell);
      }
    }
  });
  std::vector<ReconstructionError> errors(domains.size());
  tbb::parallel_for(size_t(0), domains.size(), [&](size_t d) {
    Accumulator accumulator;
    size_t scored = 0;
    for (const Row& row : rows) scored += row.scored[d];
    accumulator.Reserve(scored);
    const uint8_t bit = uint8_t(1u << d);
    for (const Row& row : rows) {
      accumulator.Outside(row.within - row.scored[d]);
      for (const Scored& cell : row.cells) {
        if ((cell.domains & bit) && cell.band >= 0) accumulator.AddRelative(cell.rel, cell.band);
      }
    }
    errors[d] = accumulator.Finish();
  });
  return errors;
}

nlohmann::json ToJson(const ReconstructionError& error) {
  auto rgb = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  return {{"cells_scored", error.points},
          {"cells_outside", error.outside},
          {"coverage", error.coverage()},
          {"rel_rms_error", rgb(error.rel_rms)},
          {"rel_rms_error_all", error.rel_rms_all},
          {"median_abs_rel_error", rgb(error.median)},
          {"p95_abs_rel_error", rgb(error.p95)},
          {"theta_h_bands", [&] {
             nlohmann::json bands = nlohmann::json::array();
             for (const ThetaHBandBias& band : error.theta_h_bands) {
               bands.push_back({{"theta_h_deg", {band.theta_h_min_deg, band.theta_h_max_deg}},
                                {"cells_scored", band.points},
                                {"mean_signed_rel_error", rgb(band.mean_rel)}});
             }
             return bands;
           }()}};
}

UncertaintyCoverage CompareUncertaintyWithTruth(const MerlTable& table, const std::vector<float>& uncertainty,
                                                const std::vector<uint8_t>& domain, uint8_t domain_class,
                                                const BrdfModel& truth, double max_theta_deg) {
  IBRDF_CHECK(uncertainty.size() == 3 * kMerlCells && domain.size() == kMerlCells)
      << "uncertainty " << uncertainty.size() << " and domain " << domain.size() << " values for " << kMerlCells
      << " cells";
  std::vector<Cell> cells = Cells(max_theta_deg, 1);
  cells.erase(std::remove_if(cells.begin(), cells.end(),
                             [&](const Cell& cell) {
                               return domain[cell.flat] != domain_class || !table.Measured(cell.flat) ||
                                      uncertainty[3 * cell.flat] < 0.0f;
                             }),
              cells.end());
  // Per cell channel: |log(f / f_true)| and the stated error (negative: not scored, -2: unbounded).
  std::vector<std::array<float, 6>> scored(cells.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const Cell& cell = cells[k];
      const Eigen::Vector3d f = table.Cell(cell.flat), t = truth.Eval(cell.wi, cell.wo);
      for (int c = 0; c < 3; ++c) {
        const float se = uncertainty[3 * cell.flat + c];
        scored[k][c] = f[c] > 0.0 && t[c] > 0.0 ? static_cast<float>(std::log(f[c] / t[c])) : NAN;
        scored[k][3 + c] = se;
      }
    }
  });
  UncertaintyCoverage out;
  std::vector<float> errors, stated;
  size_t one = 0, two = 0;
  double sum2 = 0.0;
  for (const auto& s : scored) {
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(s[c])) continue;
      if (!std::isfinite(s[3 + c])) {
        ++out.unbounded;
        continue;
      }
      const float e = std::abs(s[c]);
      ++out.values;
      one += e <= s[3 + c];
      two += e <= 2.0f * s[3 + c];
      sum2 += double(e) * e;
      errors.push_back(e);
      stated.push_back(s[3 + c]);
    }
  }
  if (out.values == 0) return out;
  out.within_1sigma = double(one) / double(out.values);
  out.within_2sigma = double(two) / double(out.values);
  out.rms_error = std::sqrt(sum2 / double(out.values));
  auto median = [](std::vector<float>* v) {
    std::nth_element(v->begin(), v->begin() + v->size() / 2, v->end());
    return double((*v)[v->size() / 2]);
  };
  out.median_error = median(&errors);
  out.median_stated = median(&stated);
  return out;
}

std::string UncertaintyCoverage::Brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "%zu cell channels: %.1f %% within 2 standard errors, %.1f %% within 1 (error median %.2f %%, RMS "
                "%.2f %%; stated median %.2f %%)",
                values, 100.0 * within_2sigma, 100.0 * within_1sigma, 100.0 * median_error, 100.0 * rms_error,
                100.0 * median_stated);
  return buffer;
}

nlohmann::json ToJson(const UncertaintyCoverage& coverage) {
  return {{"cell_channels", coverage.values},
          {"unbounded", coverage.unbounded},
          {"within_1sigma", coverage.within_1sigma},
          {"within_2sigma", coverage.within_2sigma},
          {"median_abs_log_error", coverage.median_error},
          {"rms_log_error", coverage.rms_error},
          {"median_standard_error", coverage.median_stated}};
}

std::string MerlLookupCheck::Brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "MERL lookups at %zu random direction pairs: %.1f %% hit a cell with data; among them |rel. "
                "error| median %.2f %%, 95th percentile %.2f %% (R G B pooled)",
                lookups, 100.0 * hit_fraction(), 100.0 * median.mean(), 100.0 * p95_all);
  return buffer;
}

MerlLookupCheck CheckMerlLookups(const MerlTable& table, const BrdfModel& truth, size_t lookups, double max_theta_deg,
                                 uint64_t seed) {
  MerlLookupCheck check;
  check.lookups = lookups;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double cos_limit = std::cos(max_theta_deg * M_PI / 180.0);
  // Uniform by solid angle over the cap theta <= max_theta: cos(theta) uniform in [cos_limit, 1].
  const auto direction = [&] {
    const double z = cos_limit + (1.0 - cos_limit) * uniform(rng);
    const double phi = 2.0 * M_PI * uniform(rng);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  };
  std::vector<double> channel[3], pooled;
  for (size_t n = 0; n < lookups; ++n) {
    const Eigen::Vector3d wi = direction(), wo = direction();
    const Eigen::Vector3d f = table.Lookup(wi, wo);
    if ((f.array() < 0.0).any()) continue;
    ++check.hits;
    const Eigen::Vector3d t = truth.Eval(wi, wo);
    if (!(t.array() > 0.0).all()) continue;
    ++check.scored;
    for (int c = 0; c < 3; ++c) {
      const double rel = std::abs(f[c] - t[c]) / t[c];
      channel[c].push_back(rel);
      pooled.push_back(rel);
    }
  }
  if (check.scored > 0) {
    for (int c = 0; c < 3; ++c) {
      check.median[c] = PercentileInPlace(&channel[c], 0.5);
      check.p95[c] = PercentileInPlace(&channel[c], 0.95);
    }
    check.p95_all = PercentileInPlace(&pooled, 0.95);
  }
  return check;
}

nlohmann::json ToJson(const MerlLookupCheck& check) {
  auto rgb = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  return {{"lookups", check.lookups},
          {"hits", check.hits},
          {"hit_fraction", check.hit_fraction()},
          {"scored", check.scored},
          {"median_abs_rel_error", rgb(check.median)},
          {"p95_abs_rel_error", rgb(check.p95)},
          {"p95_abs_rel_error_all", check.p95_all},
          {"directions", "wi, wo uniform by solid angle over the hemisphere, independent, fixed seed"}};
}

}  // namespace ibrdf
