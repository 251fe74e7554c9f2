// Where a point of the BRDF domain stands relative to the samples: measured, interpolated or
// unmeasured. The class is decided by where the samples are, never by the estimate's value nor its
// effective sample count (a kernel grown into empty territory can still gather many samples):
//   measured      the point lies within the samples' theta_d range, a regression point (a bin of
//                 samples) lies within `measured_nearest` kernel radii of it, its support did not have
//                 to grow, the weighted centroid of the samples in its kernel lies within
//                 `max_centroid_offset` kernel radii (samples around it, not beside it), and the
//                 estimate's stated standard error is at most `max_measured_standard_error`;
//   interpolated  within the samples' theta_d range, supported, and the centroid of the samples in its
//                 (possibly grown) kernel still within `max_centroid_offset` kernel radii: samples on
//                 several sides of a gap, so the estimate is an interpolation;
//   unmeasured    everything else: beyond the theta_d the samples reach, beside a single sheet of
//                 samples (a cylinder's incidence plane seen at another phi_d), or with no samples near.
// Distances are in the kernel's scaled units (the ellipsoid of radii radius_h_deg, radius_h_deg,
// radius_d_deg in (u, v, w), reconstruct/local_regression.h), with the mirror images of the folds.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "reconstruct/local_regression.h"

namespace ibrdf {

// The classes, as stored in domain.npy and eval_domain.npy.
enum class DomainClass : uint8_t { kUnmeasured = 0, kInterpolated = 1, kMeasured = 2 };

// "unmeasured", "interpolated", "measured".
const char* DomainClassName(DomainClass c);

struct DomainRules {
  double measured_nearest = 0.5;     // nearest regression point within this many kernel radii
  double max_centroid_offset = 0.5;  // samples' centroid within this many kernel radii (both classes)
  // The samples' theta_d range is widened by this (degrees) on each side before cells are tested
  // against it (0: a cell centre beyond the largest sampled theta_d is unmeasured).
  double theta_d_margin_deg = 0.0;
  // A cell placed as measured by the rules above is measured only if its stated standard error
  // (Estimate::standard_error, of log f: relative) is at most this in every channel; otherwise it is
  // interpolated (docs/reconstruct.md, "Per-cell uncertainty"). Infinity: no such test.
  double max_measured_standard_error = 0.02;
  bool Check(std::string* why) const;
};

// The class of estimate `e` at a point of difference angle `theta_d` (radians) of `regression`.
DomainClass ClassifyEstimate(const Estimate& e, double theta_d, const LocalRegression& regression,
                             const DomainRules& rules);

// What unmeasured points are written as.
enum class FillMode : uint8_t {
  kNone = 0,         // the format's "no data" value (-1 in MERL tables and ibrdf's arrays)
  kModel = 1,        // the fitted model chosen by the stage (lowest error against the samples)
  kExtrapolate = 2,  // the regression's own estimate (grown support, one-sided fit) where it has one
};
const char* FillModeName(FillMode mode);                      // "none", "model", "extrapolate"
bool ParseFillMode(const std::string& text, FillMode* mode);  // false on anything else

// Counts of points by class (and of unmeasured points filled).
struct DomainCounts {
  uint64_t measured = 0, interpolated = 0, unmeasured = 0;
  uint64_t filled = 0;  // unmeasured points given a value by the fill mode
  void Add(DomainClass c);
  void Merge(const DomainCounts& other);
  // "N measured, N interpolated, N unmeasured (N filled)".
  std::string Brief() const;
};
nlohmann::json ToJson(const DomainCounts& counts);

}  // namespace ibrdf
