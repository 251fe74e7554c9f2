#include "reconstruct/merl_table.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/error.h"
#include "core/file_util.h"
#include "core/logging.h"

namespace ibrdf {

bool TabulateOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(max_theta_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_deg, 90.0);
  IBRDF_CHECK_OPTION_GE(min_effective_samples, 0.0f);
  return domain.Check(why);
}

std::string TabulateSummary::BriefReport() const {
  char buffer[480];
  std::snprintf(buffer, sizeof(buffer),
                "tabulate: %s within the theta limit, %llu beyond it; samples' theta_d %.1f to %.1f deg; "
                "unmeasured cells %s; %llu evaluations in %.2f s",
                domain.Brief().c_str(), (unsigned long long)cells_below_horizon, theta_d_min_deg, theta_d_max_deg,
                fill == FillMode::kNone ? "written as -1 (no data)"
                                        : (std::string("filled by ") + FillModeName(fill) +
                                           (fill_model.empty() ? "" : " (" + fill_model + ")"))
                                              .c_str(),
                (unsigned long long)evaluations, seconds);
  return buffer;
}

MerlTable TabulateMerl(const LocalRegression& regression, const TabulateOptions& options, TabulateSummary* summary,
                       std::vector<float>* effective_samples, std::vector<uint8_t>* domain,
                       const BrdfModel* fill_model, std::vector<float>* uncertainty) {
  std::string why;
  if (!options.Check(&why)) ThrowError("tabulate options", why);
  if (options.fill == FillMode::kModel && !fill_model) ThrowError("tabulate options", "fill 'model' without a model");
  Timer timer;
  const bool mirror = regression.options().fold_bilateral;
  const int phi_count = mirror ? kMerlPhiD / 2 : kMerlPhiD;
  const double cos_limit = std::cos(options.max_theta_deg * M_PI / 180.0);
  // The cells to evaluate: inside the horizon limit; with bilateral folding, the first half of phi_d.
  std::vector<size_t> cells;
  MerlTable table;
  TabulateSummary local;
  local.fill = options.fill;
  if (fill_model && options.fill == FillMode::kModel) local.fill_model = fill_model->ModelName();
  local.theta_d_min_deg = regression.theta_d_min() * 180.0 / M_PI;
  local.theta_d_max_deg = regression.theta_d_max() * 180.0 / M_PI;
  // Per theta_h row in parallel, joined in flat index order.
  std::vector<std::vector<size_t>> row_cells(kMerlThetaH);
  std::vector<uint64_t> row_below(kMerlThetaH, 0);
  tbb::parallel_for(0, kMerlThetaH, [&](int i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        const HalfDiffAngles angles = MerlCellCentre(i, j, k);
        Eigen::Vector3d wi, wo;
        FromHalfDiff(angles, &wi, &wo);
        const bool inside = wi.z() > cos_limit && wo.z() > cos_limit && wi.z() > 0.0 && wo.z() > 0.0;
        if (!inside) {
          ++row_below[i];
          continue;
        }
        if (k >= phi_count) continue;
        row_cells[i].push_back(MerlFlatIndex(i, j, k));
      }
    }
  });
  for (int i = 0; i < kMerlThetaH; ++i) {
    local.cells_below_horizon += row_below[i];
    cells.insert(cells.end(), row_cells[i].begin(), row_cells[i].end());
  }
  if (effective_samples) effective_samples->assign(kMerlCells, 0.0f);
  if (domain) domain->assign(kMerlCells, 0);
  if (uncertainty) uncertainty->assign(3 * kMerlCells, -1.0f);
  const double margin = options.domain.theta_d_margin_deg * M_PI / 180.0;
  const double theta_d_low = regression.theta_d_min() - margin, theta_d_high = regression.theta_d_max() + margin;
  std::mutex mutex;
  // Each range's counts, merged in cell order after: the ranges are the same on every run and thread
  // count (a simple partitioner halves the cells down to the grain), so the mean effective sample
  // count is the same number every time (merged in the order ranges finished, its last bits varied).
  std::map<size_t, std::pair<ReliabilityCounts, DomainCounts>> range_counts;
  ProgressBar progress("tabulate", cells.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, cells.size(), 512),
      [&](const tbb::blocked_range<size_t>& range) {
        ReliabilityCounts reliability;
        DomainCounts counts;
        for (size_t p = range.begin(); p != range.end(); ++p) {
          const size_t flat = cells[p];
          const int k = static_cast<int>(flat % kMerlPhiD);
          const int j = static_cast<int>((flat / kMerlPhiD) % kMerlThetaD);
          const int i = static_cast<int>(flat / (size_t(kMerlPhiD) * kMerlThetaD));
          const HalfDiffAngles angles = MerlCellCentre(i, j, k);
          // Beyond the samples' theta_d range a cell is unmeasured whatever its estimate: evaluated only
          // when --fill extrapolate wants the estimate.
          const bool beyond = angles.theta_d < theta_d_low || angles.theta_d > theta_d_high;
          const Estimate e = beyond && options.fill != FillMode::kExtrapolate
                                 ? Estimate()
                                 : regression.EvaluateAt(RegressionCoordinates(angles));
          if (!beyond || options.fill == FillMode::kExtrapolate) reliability.Add(e);
          DomainClass c = ClassifyEstimate(e, angles.theta_d, regression, options.domain);
          if (e.effective_samples < options.min_effective_samples) c = DomainClass::kUnmeasured;
          Eigen::Vector3d value = e.value;
          bool has_value = c != DomainClass::kUnmeasured;
          bool regression_value = has_value;  // the value is the regression's (its standard error applies)
          if (!has_value && options.fill == FillMode::kExtrapolate && e.status != EstimateStatus::kUnsupported) {
            has_value = regression_value = true;
          } else if (!has_value && options.fill == FillMode::kModel) {
            Eigen::Vector3d wi, wo;
            FromHalfDiff(angles, &wi, &wo);
            value = fill_model->Eval(wi, wo);
            has_value = value.allFinite();
          }
          // The mirrored cell is inside the horizon whenever this one is (bilateral symmetry of the geometry).
          const int targets = mirror ? 2 : 1;
          for (int t = 0; t < targets; ++t) {
            const size_t target = t == 0 ? flat : flat - k + (kMerlPhiD - 1 - k);
            counts.Add(c);
            if (c == DomainClass::kUnmeasured && has_value) ++counts.filled;
            if (has_value) {
              table.SetCell(target, value);
            } else {
              table.SetUnmeasured(target);
            }
            if (domain) (*domain)[target] = static_cast<uint8_t>(c);
            if (effective_samples && c != DomainClass::kUnmeasured) (*effective_samples)[target] = e.effective_samples;
            if (uncertainty && regression_value) {
              for (int ch = 0; ch < 3; ++ch) (*uncertainty)[3 * target + ch] = e.standard_error[ch];
            }
          }
        }
        progress.Add(range.size());
        std::lock_guard<std::mutex> lock(mutex);
        range_counts[range.begin()] = {reliability, counts};
      },
      tbb::simple_partitioner());
  for (const auto& [begin, counts] : range_counts) {
    local.reliability.Merge(counts.first);
    local.domain.Merge(counts.second);
  }
  progress.Finish();
  local.evaluations = local.reliability.evaluations;
  local.seconds = timer.ElapsedSeconds();
  local.success = true;
  if (summary) *summary = local;
  return table;
}

std::vector<double> MerlToArray(const MerlTable& table) {
  std::vector<double> array(3 * kMerlCells);
  for (size_t flat = 0; flat < kMerlCells; ++flat) {
    const bool measured = table.Measured(flat);
    const Eigen::Vector3d value = table.Cell(flat);
    for (int c = 0; c < 3; ++c) array[3 * flat + c] = measured ? value[c] : -1.0;
  }
  return array;
}

}  // namespace ibrdf
