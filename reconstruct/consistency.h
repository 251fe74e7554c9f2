// Consistency checks of measured BRDF samples (the paper's section 4.2) in the isotropic domain
// (theta_i, theta_e, delta_phi):
//  - reciprocity: f(theta_i, theta_e, delta_phi) against f(theta_e, theta_i, -delta_phi), the same pair
//    of directions with light and camera exchanged;
//  - bilateral symmetry: f(theta_i, theta_e, delta_phi) against f(theta_i, theta_e, -delta_phi) (the JSON
//    keeps "isotropy" as an alias of "bilateral_symmetry" for one release).
// Samples are compared with samples, never with an extrapolated estimate. Each sample (side A, at its
// point p) is paired with the measured samples within `match_deg` of its image point q (side B), taken
// only where their centroid lies within a quarter of that radius of q (q is surrounded; a point at the
// edge of the measured sheets gets no partner). Where the samples suffice (side B a sample per
// parameter, both sides together two), the pair's difference is one joint weighted least-squares fit
// of log f, quadratic in the offset from q, over side B's samples as measured and side A's (those
// within `match_deg` of p) taken to their images, with one extra parameter: side A's offset delta.
// The sides share the BRDF's slope and curvature, so a sharp highlight's curvature within the radius
// (which biased a plain mean of side B by several per cent at 4 degrees) cancels, and delta is the log
// of A over B at the same exact point q; a fit that leaves delta poorly determined (variance above
// twice one sample's) gives no pair. Where the samples are fewer, at radii up to 1 degree, side B's
// plain mean is the partner (its curvature error grows as the radius squared); beyond, no pair.
// Each pair gives a signed relative difference (a - b) / ((a + b) / 2) (= 2 tanh(delta / 2) for a
// fitted pair); a bin of (theta_i, theta_e, delta_phi) reports |median of its pairs' signed
// differences| (camera noise and the remaining offsets fall on either side and cancel, a real
// violation, a bias of one sign, does not), with that median's own standard error. The headline
// figures are the median and the 95th percentile over bins, and the worst bins are listed with where
// they are.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/sample_file.h"

namespace ibrdf {

struct ConsistencyOptions {
  double theta_bin_deg = 10.0;   // bin width in theta_i and theta_e, in (0, 45]
  double phi_bin_deg = 20.0;     // bin width in delta_phi, divides 360
  int min_samples_per_bin = 20;  // sample pairs a bin needs to be reported (CLI --min-pairs)
  double max_theta_deg = 80.0;   // samples beyond this theta_i or theta_e are not compared
  // Partners lie within this angle of the reciprocal (mirrored) point, [0.01, 5]; 0: automatic, the
  // first of 0.5, 1, 2 and 4 degrees at which both figures have kAutoMinBins bins (sparse sample sets,
  // e.g. a derender stride, need a wider radius).
  double match_deg = 0.0;
  int worst_bins = 5;  // the worst bins listed in the report, [0, 100]
  // False with `*why` naming the failing constraint.
  bool Check(std::string* why) const;
};

// One bin's pairs.
struct BinComparison {
  Eigen::Vector3d center_deg;        // (theta_i, theta_e, delta_phi) of the bin's centre, degrees
  int count_a = 0, count_b = 0;      // sample pairs in the bin (both: one pair per sample of the bin)
  Eigen::Vector3d value_a, value_b;  // median RGB of the bin's samples and of their partners (1/sr)
  Eigen::Vector3d rel_error;         // per channel, |median over pairs of (a - b) / ((a + b) / 2)|
  // Per channel, the standard error of that median from the pairs' spread (sqrt(pi / 2) 1.4826 MAD /
  // sqrt(pairs)); pairs that share samples are not independent, so take it as a lower bound.
  Eigen::Vector3d rel_error_se = Eigen::Vector3d::Zero();
  double mean_rel_error = 0.0;     // over the channels
  double mean_rel_error_se = 0.0;  // over the channels
};

// One check's bins and headline figures.
struct ConsistencyFigure {
  std::vector<BinComparison> bins;
  size_t pairs = 0;                // sample pairs in reported bins
  size_t fitted_pairs = 0;         // of those, the pairs whose partner is the joint fit (not the mean)
  double overall_rel_error = 0.0;  // the headline: the median over bins of mean_rel_error
  Eigen::Vector3d per_channel_rel_error = Eigen::Vector3d::Zero();  // per channel, median over bins
  double median_rel_error = 0.0;                                    // = overall_rel_error
  double p95_rel_error = 0.0;                                       // the 95th percentile over bins
  double median_bin_se = 0.0;  // the median over bins of mean_rel_error_se: the figures' own error bar
  std::vector<size_t> worst;   // indices into `bins`, worst first
  bool valid() const { return !bins.empty(); }
  // "0.12 % median, 0.80 % p95 over 312 bins (worst 2.1 % at theta_i 15, theta_e 45, delta_phi 170 deg)",
  // or "invalid: no bin had N sample pairs".
  std::string Headline(int min_pairs) const;
};

// Both checks of a sample set.
struct ConsistencyReport {
  static constexpr size_t kAutoMinBins = 20;
  bool success = false;
  size_t samples = 0;
  double match_deg = 0.0;  // the radius used
  int min_pairs = 0;       // the options' min_samples_per_bin, for the headlines
  ConsistencyFigure reciprocity;
  ConsistencyFigure bilateral_symmetry;
  // One line: both headlines.
  std::string BriefReport() const;
};

// Pairs every sample with its reciprocal and mirrored neighbourhoods and bins the pairs. Throws Error
// on invalid options.
ConsistencyReport CheckConsistency(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options);

// The report as `ibrdf check` writes it (format "ibrdf-consistency" version 2).
nlohmann::json ToJson(const ConsistencyReport& report, const ConsistencyOptions& options);

struct PredictionCheckOptions;
struct PredictionReport;

// The local-regression check's one line: each figure's median and 95th percentile over its pairs, or
// "invalid" where it has none (never "0.00 % over 0 pairs").
std::string RegressionSummary(const PredictionReport& report);

// `ibrdf check`'s report: the paired figures (CheckConsistency, ToJson) and, with `prediction`, the
// local-regression checks (reconstruct/prediction_check.h) under "regression". Logs both summaries (a
// figure without pairs as "invalid", never as "0.00 %"). `report` (optional) gets the figures.
nlohmann::json CheckSamples(const std::vector<BrdfSample>& samples, const ConsistencyOptions& options,
                            const PredictionCheckOptions* prediction, ConsistencyReport* report = nullptr);

}  // namespace ibrdf
