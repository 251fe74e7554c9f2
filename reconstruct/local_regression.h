// Local polynomial regression of scattered BRDF samples into a smooth isotropic BRDF (the paper's
// section 3.3: an elliptical kernel long enough to bridge the sheets of samples that each photo
// contributes, short along them).
//
// Coordinates. Each sample's pair of directions is converted to Rusinkiewicz's half/difference angles
// (core/brdf_coords.h, as the MERL reader computes them) and then to
//   u = theta_h cos(phi_d),  v = theta_h sin(phi_d),  w = theta_d.
// A photo of a convex sample under one distant light sees (nearly) one angle between wi and wo, and
// theta_d is half that angle, so each photo's samples form a slab of nearly constant w: the kernel is
// long in w (across the sheets) and short in (u, v) (along them), an axis-aligned ellipsoid. (u, v) is
// the half vector in polar form about d's azimuth, which stays smooth at theta_h = 0 where phi_d is
// undefined, so the normal-incidence peak is not a coordinate singularity.
//
// Symmetries. Reciprocity (wi <-> wo) maps phi_d to phi_d + pi, i.e. (u, v) -> (-u, -v); bilateral
// symmetry (delta_phi -> -delta_phi) maps phi_d to -phi_d, i.e. v -> -v. With folding on, samples are
// mapped into the canonical part of the domain and every evaluation also gathers the mirrored images of
// its neighbourhood, so there is no artificial boundary at the fold. Folding can be switched off to
// check the symmetries instead of assuming them (reconstruct/prediction_check.h).
//
// Each evaluation fits a polynomial of degree 0, 1 or 2 in the bandwidth-scaled offsets with tricube
// weights (1 - r^3)^3 (as locfit) and returns its constant term, with a reliability: the neighbour
// count, the effective sample count (sum w)^2 / sum w^2, the reciprocal condition of the normal
// matrix, the degree actually used and whether the support had to grow. It never returns NaN.
//
// Speed. Samples are aggregated into small grid cells (LocalRegressionOptions::bin_fraction_*) that
// enter the fit as weighted points at their centroids, so an evaluation costs the cells in its kernel,
// not the samples: the full MERL grid from ~9 M samples tabulates in ~20 s on 2 cores.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/brdf_coords.h"
#include "core/sample_file.h"

namespace ibrdf {

struct LocalRegressionOptions {
  int degree = 2;                // 0 local constant, 1 local linear, 2 local quadratic
  double radius_h_deg = 2.5;     // kernel radius along the sheets, in u and v (degrees of theta_h)
  double radius_d_deg = 9.0;     // kernel radius across the sheets, in w = theta_d (degrees)
  bool fold_reciprocity = true;  // assume f(wi, wo) = f(wo, wi) and pool both halves
  bool fold_bilateral = true;    // assume f(delta_phi) = f(-delta_phi) and pool both halves
  // Fit log f instead of f (a Phong/Lafortune lobe is close to exp of a quadratic); samples <= 0 are
  // clamped to `log_floor` first. On by default: 0.84 % against 1.63 % RMS on noise-free bluepaint.
  bool log_space = true;
  double log_floor = 1e-6;  // 1/sr
  // In log space, correct each sample's log value for the noise's curvature bias: E[log f] falls short
  // of log E[f] by about (sigma / f)^2 / 2, so 0.5 (sigma / f)^2 is added (capped at
  // max_log_noise_correction); samples without sigma are left as they are. A dim channel kept with its
  // noise (per-channel validity) would otherwise come out low: -2 % at 20 % noise per sample.
  bool log_noise_correction = true;
  double max_log_noise_correction = 0.125;  // the correction at sigma / f = 0.5
  // A degree is used only if the normal matrix's reciprocal condition (LDLT estimate) is above this and
  // the effective sample count is at least `min_samples_per_coefficient` times the coefficient count;
  // otherwise the next lower degree is tried.
  double min_rcond = 1e-10;
  double min_samples_per_coefficient = 1.5;
  // A degree is also rejected when its estimate leaves the range [min, max] of the neighbours' values
  // widened by this fraction of the range on each side (an extrapolation).
  double range_margin = 1.0;
  // A degree is used only if its estimate has at least this many effective samples, 1 / sum l_i^2 for
  // the estimate sum l_i f_i (the noise of one sample is reduced by this factor in variance).
  double min_fit_samples = 3.0;
  // Where the kernel holds fewer than `min_neighbors` samples, the support grows to reach the
  // `min_neighbors` nearest ones (at most `max_growth` times the radii; beyond that the point is
  // reported as unsupported, value 0).
  int min_neighbors = 12;
  double max_growth = 4.0;
  // Clamp negative estimates (extrapolated slopes) to 0; they are counted.
  bool clamp_negative = true;
  // Binning (data reduction for millions of samples). Samples are aggregated into grid cells of these
  // edges, as fractions of the kernel radii (along the sheets in u and v, across them in w); each cell
  // enters the fit as its sample count times one sample at the cells' centroid with the cells' mean
  // value (sum of weights, sum of squared weights and neighbour counts stay per sample). The cost of
  // an evaluation is then bounded by the cells in the kernel, not the samples, while no sample is
  // discarded; the approximation is second order in the cell edge. 0 turns binning off (every sample
  // its own point). Measured in docs/benchmarks.md, "Reconstruct".
  double bin_fraction_h = 0.2;
  double bin_fraction_d = 0.1;
  // Standard errors (Estimate::standard_error): the noise of the estimate from the residual variance
  // about the fit and its weights, and its bias from the disagreement with the same degree's fit in a
  // kernel `bias_shrink` times as large (computed from the same neighbours), extrapolated to the full
  // kernel as a bias of order h^(degree + 1), with that difference's own noise subtracted
  // (docs/reconstruct.md, "Per-cell uncertainty"). Off: standard_error stays infinite
  // (cross-validation never computes it).
  // Where the degree had to be reduced, the bias is also measured against the requested degree fitted
  // in a kernel this many times larger (more sheets of samples: the trend the reduced fit cannot see).
  bool standard_errors = true;
  double bias_shrink = 0.6;
  double bias_wide_growth = 3.0;

  bool Check(std::string* why) const;
};

// Why an estimate is less than a full-degree fit inside the kernel.
enum class EstimateStatus : uint8_t {
  kFull = 0,           // the requested degree with the given radii
  kReducedDegree = 1,  // an ill-conditioned design: a lower degree was used
  kGrown = 2,          // too few samples in the kernel: the support grew (maybe the degree dropped too)
  kUnsupported = 3,    // no sample within max_growth times the radii: value 0
};

struct Estimate {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();  // RGB BRDF, 1/sr; always finite
  // 1 / sum l_i^2 for the estimate sum l_i f_i: how many samples' worth of noise averaging the fit
  // achieves ((sum w)^2 / sum w^2 for a local constant).
  float effective_samples = 0.0f;
  float rcond = 0.0f;   // reciprocal condition estimate of the normal matrix used
  float growth = 1.0f;  // factor applied to the radii (1 = as given)
  // Distance from the query to the weighted centroid of the samples in its kernel, in kernel radii (as
  // given, before growth). Inside sampled territory it is small; a query beside a single sheet (a
  // cylinder's incidence plane) or beyond the edge of the data is an extrapolation and has a large one.
  float centroid_offset = 0.0f;
  // Distance from the query to the nearest point of the regression (a bin's centroid, or a sample
  // without binning) inside the final support, in kernel radii as given; infinity when there is none.
  float nearest = std::numeric_limits<float>::infinity();
  // One-sigma standard error per channel of log f (the relative error of f; in linear space the
  // standard error of f divided by f): sqrt(noise variance + bias^2) (LocalRegressionOptions::
  // standard_errors). Infinite when not computed or unsupported.
  Eigen::Vector3f standard_error = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  uint32_t neighbors = 0;  // samples with non-zero weight (mirrored images included)
  int8_t degree = -1;      // degree used; -1 when unsupported
  EstimateStatus status = EstimateStatus::kUnsupported;
  bool clamped = false;  // a negative estimate was clamped to 0
};

// Cross-validation figures of one fit, each averaged over a subset of the samples and the 3 channels.
// Residuals are taken in the fitting space: r_i = log f^(x_i) - log f_i with log values (about the
// relative error), (f^(x_i) - f_i) / max(f_i, 1e-4) with linear values.
struct CrossValidationScore {
  size_t points = 0;  // samples scored
  // Leave-one-out: RMS of the residual of the fit without sample i, at x_i.
  double loo_rms = 0.0;
  // RMS of the ordinary residual (sample i in the fit).
  double residual_rms = 0.0;
  // Mean leverage, the mean of the hat matrix's diagonal l_ii = dF^(x_i)/df_i (the weight of sample i in
  // the estimate at its own position): tr(L) / n, estimated on the subset.
  double mean_leverage = 0.0;
  // Generalized cross-validation (Craven and Wahba 1979), as a root mean square:
  // sqrt(GCV) = residual_rms / (1 - tr(L) / n), i.e. GCV = n sum r_i^2 / (n - tr L)^2.
  double gcv_rms = 0.0;
};

// The measured domain of an error figure: estimates that neither had to grow their support nor lie
// farther than this from the centroid of their samples (in kernel radii): interpolations, not
// extrapolations (docs/reconstruct.md, "Measured domain").
constexpr double kMeasuredDomainMaxCentroidOffset = 0.5;
bool InMeasuredDomain(const Estimate& e);

// Counts of evaluations by status, for summaries ("how many evaluations fell back").
struct ReliabilityCounts {
  uint64_t evaluations = 0, full = 0, reduced_degree = 0, grown = 0, unsupported = 0, clamped = 0;
  double mean_effective_samples = 0.0;
  void Add(const Estimate& e);
  void Merge(const ReliabilityCounts& other);
  std::string Brief() const;
};
nlohmann::json ToJson(const ReliabilityCounts& counts);

// The regression coordinates (u, v, w) of a direction pair, in radians (see the header comment).
Eigen::Vector3d RegressionCoordinates(const HalfDiffAngles& angles);
Eigen::Vector3d RegressionCoordinates(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo);

class LocalRegression {
 public:
  // Converts and folds the samples and builds the kd-tree (TBB-parallel conversion). Samples with a
  // non-finite value or direction are skipped and counted. Per-channel validity (BrdfSample::valid):
  // a channel that some samples did not measure is regressed on its own from the samples that did
  // (a second regression per such channel, built the same way), so an unmeasured value never enters
  // a fit; the channels every sample measured share this one.
  LocalRegression(const std::vector<BrdfSample>& samples, const LocalRegressionOptions& options);
  // As above without the samples whose `leave_out` flag is non-zero (one flag per sample), the same
  // regression as of a copy holding only the others: a held-out photo's fit without copying the rest.
  LocalRegression(const std::vector<BrdfSample>& samples, const std::vector<uint8_t>& leave_out,
                  const LocalRegressionOptions& options);
  ~LocalRegression();
  LocalRegression(const LocalRegression&) = delete;
  LocalRegression& operator=(const LocalRegression&) = delete;

  // The estimate for one pair of local directions (towards the light, towards the camera).
  Estimate Evaluate(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const;
  Estimate Evaluate(const HalfDiffAngles& angles) const;
  // At regression coordinates (u, v, w); `exclude` is a sample index left out of the fit (for
  // leave-one-out), or -1 (it indexes the shared regression; per-channel ones leave nothing out). With
  // per-channel regressions the reliability fields are the least favourable over the channels.
  Estimate EvaluateAt(const Eigen::Vector3d& uvw, int64_t exclude = -1) const;
  // Many points, TBB-parallel; `counts` (optional) gets their reliability counts.
  std::vector<Estimate> EvaluateMany(const std::vector<Eigen::Vector3d>& uvw, ReliabilityCounts* counts) const;

  // Cross-validation scores at `count` samples chosen with a fixed seed (for bandwidth selection,
  // reconstruct/bandwidth_selection.h); the left-out sample is taken out of its bin exactly. With
  // per-channel regressions: the mean of their scores, weighted by the channels each serves.
  CrossValidationScore CrossValidate(size_t count, uint64_t seed = 1) const;

  size_t size() const;    // samples used (by the shared regression)
  size_t points() const;  // points in the kd-tree: occupied bins (or samples without binning)
  uint64_t skipped_samples() const { return skipped_; }
  // Channels regressed on their own because some samples did not measure them (bit c for channel c).
  int separate_channels() const;
  // The range of theta_d (radians) the samples cover; both 0 without samples.
  double theta_d_min() const;
  double theta_d_max() const;
  const LocalRegressionOptions& options() const { return options_; }

 private:
  // The fit at `uvw` without sample `exclude` (-1: none); `leverage` (optional) gets the weight of sample
  // `self` in the estimate (0 when it is not in the kernel).
  Estimate Fit(const Eigen::Vector3d& uvw, int64_t exclude, int64_t self, double* leverage) const;
  // The constructors' work: `leave_out` (null: none) flags the samples left out.
  void Build(const std::vector<BrdfSample>& samples, const std::vector<uint8_t>* leave_out);

  CrossValidationScore CrossValidateShared(size_t count, uint64_t seed) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
  LocalRegressionOptions options_;
  uint64_t skipped_ = 0;
  // Per-channel validity: channel c's regression from the samples that measured it (null: shared).
  std::unique_ptr<LocalRegression> channel_regressions_[3];
};

}  // namespace ibrdf
