// A reconstructed BRDF against a known true BRDF (synthetic sessions): relative RMS error over the MERL
// cell centres of the measured domain, theta_i and theta_e up to a limit (80 degrees, the derenderer's
// grazing limit) where the estimate interpolates its samples (InMeasuredDomain: estimates that had to
// grow their support, or that extrapolate beside a single sheet or beyond the data's edge, are counted
// but not scored).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/brdf_model.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"

namespace ibrdf {

// The signed relative error of one band of theta_h (the bias, which averaging over the whole domain
// hides: a channel reconstructed high where it was dim).
struct ThetaHBandBias {
  double theta_h_min_deg = 0.0, theta_h_max_deg = 0.0;
  size_t points = 0;                                   // cells scored in the band
  Eigen::Vector3d mean_rel = Eigen::Vector3d::Zero();  // mean of (f - f_true) / f_true per channel
};

struct ReconstructionError {
  size_t points = 0;   // cells scored
  size_t outside = 0;  // cells within the theta limit left out (no samples within the kernel)
  Eigen::Vector3d rel_rms = Eigen::Vector3d::Zero();  // per channel, of (f - f_true) / f_true
  double rel_rms_all = 0.0;                           // over channels
  Eigen::Vector3d median = Eigen::Vector3d::Zero();   // of |f - f_true| / f_true
  Eigen::Vector3d p95 = Eigen::Vector3d::Zero();      // 95th percentile of |f - f_true| / f_true
  std::vector<ThetaHBandBias> theta_h_bands;          // 10-degree bands of theta_h, 0 to 90
  double coverage() const { return points + outside ? double(points) / double(points + outside) : 0.0; }
  std::string Brief() const;
};

// Evaluates the regression at every `stride`-th cell centre (in each index) with theta up to the limit.
ReconstructionError CompareRegressionWithTruth(const LocalRegression& regression, const BrdfModel& truth,
                                               double max_theta_deg = 80.0, int stride = 1);
// The same over a tabulated MERL table: unmeasured cells count as outside, and so do cells outside
// `measured_domain` (from TabulateMerl) when it is given; without it every tabulated cell is scored.
ReconstructionError CompareTableWithTruth(const MerlTable& table, const BrdfModel& truth, double max_theta_deg = 80.0,
                                          const std::vector<uint8_t>* measured_domain = nullptr);
// Several such comparisons of one table at once, one per entry of `domains` (nullptr: every tabulated
// cell): the cell centres and the truth are evaluated once (TBB-parallel); each result equals
// CompareTableWithTruth with that domain.
std::vector<ReconstructionError> CompareTableWithTruth(const MerlTable& table, const BrdfModel& truth,
                                                       double max_theta_deg,
                                                       const std::vector<const std::vector<uint8_t>*>& domains);

nlohmann::json ToJson(const ReconstructionError& error);

// How well a table's stated standard errors (uncertainty.npy: of log f, per cell and channel) cover its
// true errors: over the cells of one class holding the regression's value with theta_i, theta_e within
// the limit, each channel where the truth and the value are positive and the error is finite, the
// fraction with |log(f / f_true)| within 1 and 2 standard errors (the 2-sigma band's coverage; 95 % for a
// Gaussian error stated exactly).
struct UncertaintyCoverage {
  size_t values = 0;            // cell channels scored
  size_t unbounded = 0;         // cell channels left out: infinite standard error
  double within_1sigma = 0.0;   // fraction
  double within_2sigma = 0.0;   // fraction
  double median_error = 0.0;    // of |log(f / f_true)|
  double median_stated = 0.0;   // of the standard error
  double rms_error = 0.0;       // of log(f / f_true)
  std::string Brief() const;
};
UncertaintyCoverage CompareUncertaintyWithTruth(const MerlTable& table, const std::vector<float>& uncertainty,
                                                const std::vector<uint8_t>& domain, uint8_t domain_class,
                                                const BrdfModel& truth, double max_theta_deg = 80.0);
nlohmann::json ToJson(const UncertaintyCoverage& coverage);

// What a renderer or a colleague doing MERL lookups (BRDFRead.cpp's lookup_brdf_val) at random
// directions gets from a table: wi and wo drawn uniformly (by solid angle) and independently over the
// hemisphere up to max_theta_deg (fixed seed); a lookup hits a valid cell when the cell holds data
// (>= 0); among hits, the relative error against the truth (where the truth is positive).
struct MerlLookupCheck {
  size_t lookups = 0;                                // direction pairs drawn
  size_t hits = 0;                                   // lookups that landed on a cell with data
  size_t scored = 0;                                 // hits scored (truth positive in every channel)
  Eigen::Vector3d median = Eigen::Vector3d::Zero();  // of |f - f_true| / f_true among hits
  Eigen::Vector3d p95 = Eigen::Vector3d::Zero();
  double p95_all = 0.0;  // over the channels pooled
  double hit_fraction() const { return lookups ? double(hits) / double(lookups) : 0.0; }
  std::string Brief() const;
};
MerlLookupCheck CheckMerlLookups(const MerlTable& table, const BrdfModel& truth, size_t lookups = 200000,
                                 double max_theta_deg = 90.0, uint64_t seed = 1);
nlohmann::json ToJson(const MerlLookupCheck& check);

}  // namespace ibrdf
