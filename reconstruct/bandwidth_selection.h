// Bandwidth selection for the local regression (reconstruct/local_regression.h) by leave-one-out or
// generalized cross-validation over a family of kernels.
//
// Candidates. The kernel's two radii are scaled together by each factor in `scales` (one bandwidth
// parameter, the aspect ratio kept). Both criteria score the fit at samples, i.e. on the sheets each
// photo contributes; a kernel too short across the sheets shows up only through the variance it adds
// there, not through the gaps between sheets it leaves (those are reported by the estimates' growth
// counts instead), which is why the radii are not selected independently.
//
// Criteria (CrossValidationScore, residuals in the fitting space: log f by default):
//   LOO: sqrt(mean_i r_(-i)^2), r_(-i) the residual at x_i of the fit without sample i;
//   GCV: sqrt(n sum r_i^2 / (n - tr L)^2) = residual_rms / (1 - tr(L) / n), with tr(L) = sum_i l_ii,
//        l_ii the leverage of sample i (its weight in the local fit at x_i: w(x_i - c) b(x_i - c)' A^-1 e1
//        for the bin centroid c holding it, summed over mirror images) (Craven and Wahba 1979; Loader
//        1999, section 2.3).
// Both are estimated on the same fixed-seed subset of `samples` samples.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/sample_file.h"
#include "reconstruct/local_regression.h"

namespace ibrdf {

enum class BandwidthCriterion {
  kLeaveOneOut,                 // "loo"
  kGeneralizedCrossValidation,  // "gcv"
};
// "loo" or "gcv"; false otherwise.
bool ParseBandwidthCriterion(const std::string& name, BandwidthCriterion* criterion);
const char* BandwidthCriterionName(BandwidthCriterion criterion);

struct BandwidthSelectionOptions {
  BandwidthCriterion criterion = BandwidthCriterion::kLeaveOneOut;
  // Factors applied to both kernel radii of the base options; one candidate each.
  std::vector<double> scales = {0.5, 0.7, 1.0, 1.4, 2.0};
  // Samples at which each candidate is scored (fixed seed).
  size_t samples = 4000;
  uint64_t seed = 1;
  bool Check(std::string* why) const;
};

// One candidate kernel and its scores.
struct BandwidthCandidate {
  double scale = 1.0;
  double radius_h_deg = 0.0, radius_d_deg = 0.0;
  CrossValidationScore score;
  double criterion = 0.0;  // the selected criterion's value (loo_rms or gcv_rms)
};

struct BandwidthSelection {
  bool success = false;
  BandwidthCriterion criterion = BandwidthCriterion::kLeaveOneOut;
  LocalRegressionOptions selected;        // the base options with the best candidate's radii
  std::vector<BandwidthCandidate> curve;  // every candidate, in the order of `scales`
  size_t best = 0;                        // index into curve
  double seconds = 0.0;
  std::string BriefReport() const;
  // The criterion curve, one line per candidate, for the log.
  std::string CurveTable() const;
};

// Scores every candidate (a LocalRegression is built for each) and selects the one with the smallest
// criterion.
BandwidthSelection SelectBandwidth(const std::vector<BrdfSample>& samples, const LocalRegressionOptions& base,
                                   const BandwidthSelectionOptions& options);

nlohmann::json ToJson(const BandwidthSelection& selection);

}  // namespace ibrdf
