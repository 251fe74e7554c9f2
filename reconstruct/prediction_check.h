// Consistency checks that use the local regression (the paper's section 4):
//  - held-out photos: fit without one photo's samples (the sample file's `image` column), predict
//    that photo's samples and report the error; a whole sheet is missing, so this measures how well
//    the kernel bridges the gaps between sheets;
//  - reciprocity near the incidence plane: with no folding, the fixed-incidence curve f(t0, t, dphi)
//    against the fixed-exitance curve f(t, t0, -dphi), dphi near 0 and pi;
//  - bilateral symmetry: f(ti, te, dphi) against f(ti, te, -dphi) over the domain.
// Every figure is per colour channel as well as overall.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/sample_file.h"
#include "reconstruct/local_regression.h"

namespace ibrdf {

struct PredictionCheckOptions {
  LocalRegressionOptions regression;     // folding is switched off for the symmetry figures
  int held_out_photos = 3;               // photos to hold out, evenly spaced over the images (0: none)
  size_t max_predicted_samples = 20000;  // of each held-out photo, a fixed-seed subset
  double max_theta_deg = 70.0;           // points compared (both symmetry checks) stay below this
  double near_plane_deg = 10.0;          // reciprocity: |dphi| or |pi - dphi| up to this
  double step_deg = 5.0;                 // spacing of the compared points
  float min_effective_samples = 10.0f;   // both estimates of a pair need this many, and a full fit
  bool Check(std::string* why) const;
};

struct PairFigure {
  size_t pairs = 0;
  Eigen::Vector3d mean_rel_error = Eigen::Vector3d::Zero();  // per channel, |a - b| / ((a + b) / 2)
  double mean = 0.0, median = 0.0, p95 = 0.0;                // of the channel-mean error
  bool valid() const { return pairs > 0; }
};

struct HeldOutPhoto {
  uint32_t image = 0;
  size_t predicted = 0;  // samples predicted
  // Per channel: the predicted samples that measured it (valid[c]); the channel's figures are over
  // these only, and absent (not 0) where there are none.
  Eigen::Matrix<size_t, 3, 1> measured = Eigen::Matrix<size_t, 3, 1>::Zero();
  Eigen::Vector3d rms_rel_error = Eigen::Vector3d::Zero();     // of (prediction - sample) / sample
  Eigen::Vector3d median_rel_error = Eigen::Vector3d::Zero();  // of |prediction - sample| / sample
  double within_2_sigma = -1.0;  // fraction of values within 2 sigma of the prediction (-1: no sigma)
  ReliabilityCounts reliability;
  // Whether anything was predicted: a photo with no samples below max_theta_deg (or none measured) has
  // no error figures, and says so instead of reporting 0.
  bool valid() const { return measured.maxCoeff() > 0; }
  std::string note;  // why it is not valid ("" when it is)
};

struct PredictionReport {
  bool success = false;
  PairFigure reciprocity;  // near the incidence plane
  PairFigure bilateral;
  std::vector<HeldOutPhoto> held_out;
  Eigen::Vector3d held_out_rms = Eigen::Vector3d::Zero();  // over all held-out samples (their measured channels)
  Eigen::Matrix<size_t, 3, 1> held_out_measured = Eigen::Matrix<size_t, 3, 1>::Zero();  // values behind it
  // Whether any held-out value was predicted (held_out_rms means something).
  bool held_out_valid() const { return held_out_measured.maxCoeff() > 0; }
  double seconds = 0.0;
  std::string BriefReport() const;
};

// The photos held out by CheckWithRegression with `count` held-out photos: `count` (at most the photos
// present, none with one photo) evenly spaced over the image indices present in `samples`.
std::vector<uint32_t> HeldOutImages(const std::vector<BrdfSample>& samples, int count);

// The held-out photos' line of the check's summary: their RMS prediction error per channel ("n/a" for a
// channel nothing measured), "nothing predicted" when no photo had a sample to predict, and each photo
// left out with why.
std::string HeldOutHeadline(const PredictionReport& report);

PredictionReport CheckWithRegression(const std::vector<BrdfSample>& samples, const PredictionCheckOptions& options);

nlohmann::json ToJson(const PredictionReport& report, const PredictionCheckOptions& options);

}  // namespace ibrdf
