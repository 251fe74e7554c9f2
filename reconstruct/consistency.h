// Consistency checks of measured BRDF samples (the paper's section 4.2), binned in the isotropic domain
// (theta_i, theta_e, delta_phi):
//  - reciprocity: f(theta_i, theta_e, delta_phi) against f(theta_e, theta_i, -delta_phi), the same pair
//    of directions with light and camera exchanged;
//  - bilateral symmetry (isotropy): f(theta_i, theta_e, delta_phi) against f(theta_i, theta_e, -delta_phi).
// Each bin's value is estimated at the bin centre by a local linear least-squares fit of its samples
// (minimum-norm where the samples lie on a sheet), so a BRDF's slope across a bin does not read as an
// inconsistency; paired bins' estimates are compared as |a - b| / ((a + b) / 2).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/sample_file.h"

namespace ibrdf {

struct ConsistencyOptions {
  // Bins wide enough that camera noise averages out (a bin of the default synthetic sphere session
  // holds thousands of samples); the local linear fit removes the BRDF's slope across them.
  double theta_bin_deg = 10.0;   // bin width in theta_i and theta_e
  double phi_bin_deg = 20.0;     // bin width in delta_phi
  int min_samples_per_bin = 50;  // a bin with fewer samples is not compared
  double max_theta_deg = 80.0;   // bins beyond this are not compared
  bool Check(std::string* why) const;
};

// One compared pair of bins.
struct BinComparison {
  Eigen::Vector3d center_deg;        // (theta_i, theta_e, delta_phi) of the first bin's centre
  int count_a = 0, count_b = 0;      // samples in the two bins
  Eigen::Vector3d value_a, value_b;  // RGB estimates at the bin centres (1/sr)
  Eigen::Vector3d rel_error;         // per channel, |a - b| / ((a + b) / 2)
  double mean_rel_error = 0.0;       // over the channels
};

struct ConsistencyFigure {
  std::vector<BinComparison> bins;
  // Over bin pairs, weighted by the smaller sample count of each pair.
  double overall_rel_error = 0.0;
  Eigen::Vector3d per_channel_rel_error = Eigen::Vector3d::Zero();
  double median_rel_error = 0.0;
  double p95_rel_error = 0.0;
  bool valid() const { return !bins.empty(); }
};

struct ConsistencyReport {
  bool success = false;
  size_t samples = 0;
  ConsistencyFigure reciprocity;
  ConsistencyFigure isotropy;
  std::string BriefReport() const;
};

ConsistencyReport CheckConsistency(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options);

nlohmann::json ToJson(const ConsistencyReport& report, const ConsistencyOptions& options);

struct PredictionCheckOptions;

// `ibrdf check`'s report: the binned figures (CheckConsistency, ToJson) and, with `prediction`, the
// local-regression checks (reconstruct/prediction_check.h) under "regression". Logs both summaries and
// a warning for each figure no bin pair had enough samples for. `report` (optional) gets the figures.
nlohmann::json CheckSamples(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options,
                            const PredictionCheckOptions* prediction, ConsistencyReport* report = nullptr);

}  // namespace ibrdf
