// Predicted coverage of the BRDF domain by a set of photos, before any photo is derendered: for each
// posed view, the pixels that would see the sample (a subsampled pixel grid, rays through the camera
// model onto the analytic sphere or cylinder), lit and within the derenderer's grazing limits, become
// predicted samples (directions only, value 1); the reconstruction's own regression and domain rules
// (reconstruct/local_regression.h, reconstruct/sample_domain.h, reconstruct/merl_table.h) then classify
// every MERL cell as measured, interpolated or unmeasured, exactly as `ibrdf reconstruct` classifies the
// cells of the real samples. No occlusion is modelled: a convex sample never shadows itself, and other
// objects (markers, the light's stand) are not in the session. Masks, clipping and the signal floor are
// not predicted either (they need the photos): the prediction is an upper bound where they bite.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/camera.h"
#include "core/light.h"
#include "core/rigid3.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"

namespace ibrdf {

// One posed view: where the camera stands and the light it is lit by.
struct CoverageView {
  Rigid3d camera_from_world;
  Light light;
};

struct CoverageOptions {
  // Pixel rays per view: a regular pixel grid over the sample's image, its stride chosen so that about
  // this many rays hit the sample. Each predicted sample then stands for stride^2 pixels, and the
  // regression's min_neighbors is divided by that (at least 1), so a kernel's sample count is judged
  // as it would be with every pixel.
  int samples_per_view = 12000;
  // The derenderer's grazing limits (derender/derenderer.h, DerenderOptions): degrees.
  double max_theta_i_deg = 80.0;
  double max_theta_e_deg = 80.0;
  // The reconstruction's kernel and binning (ReconstructOptions::regression's defaults).
  LocalRegressionOptions regression;
  // The reconstruction's domain rules; cells beyond max_theta_deg (theta_i or theta_e) are not counted:
  // 80 degrees, where the reconstruction's error against a truth is scored.
  TabulateOptions tabulate = [] {
    TabulateOptions t;
    t.max_theta_deg = 80.0;
    return t;
  }();
  // Bands of theta_h (degrees) for the per-band figures.
  double band_deg = 10.0;
  bool Check(std::string* why) const;
};

// Cells of one theta_h band (MERL cell centres with band_low <= theta_h < band_high), within the theta limit.
struct CoverageBand {
  double theta_h_low_deg = 0.0, theta_h_high_deg = 0.0;
  uint64_t cells = 0, measured = 0, interpolated = 0;
};

// What the prediction found; reads as failure until it ran.
struct CoverageResult {
  bool success = false;
  uint64_t views = 0;
  uint64_t samples = 0;      // predicted samples (subsampled pixels) over all views
  double pixel_stride = 0;   // the grid stride used (pixels), the largest over the views
  uint64_t cells = 0;        // MERL cells within the theta limit
  uint64_t measured = 0, interpolated = 0;
  double theta_d_min_deg = 0.0, theta_d_max_deg = 0.0;  // the predicted samples' theta_d range
  std::vector<CoverageBand> bands;
  std::vector<uint8_t> domain;  // kMerlCells DomainClass values (0 beyond the theta limit), as domain.npy
  double seconds = 0.0;
  double MeasuredFraction() const { return cells ? double(measured) / double(cells) : 0.0; }
  // "N views, N samples: measured M % (N of N cells), interpolated I %".
  std::string BriefReport() const;
};
nlohmann::json ToJson(const CoverageResult& result);

// Traces views of one camera and sample: the camera's rays come from a lattice of its undistorted
// image-plane points every 4 pixels, interpolated bilinearly (the lens model is smooth; a prediction
// needs no more), built once for all the views.
class ViewTracer {
 public:
  // Throws Error for a mesh sample (its normals need the scanned mesh; where it is not convex, its shadows).
  ViewTracer(const Camera& camera, const SampleSpec& sample, const CoverageOptions& options);
  ~ViewTracer();
  ViewTracer(const ViewTracer&) = delete;
  ViewTracer& operator=(const ViewTracer&) = delete;

  // The predicted samples of `view`, image index `image`: a pixel grid of stride `stride` (pixels,
  // >= 1; positions at pixel centres (x + 0.5, y + 0.5) as the derenderer's), each ray's hit on the
  // shape kept when lit and within the grazing limits. wi, wo in the local frame of the normal
  // (LocalFrame::FromNormal, as the derenderer), brdf 1, sigma 0.
  std::vector<BrdfSample> Samples(const CoverageView& view, double stride, uint32_t image) const;
  // The stride (pixels, >= 1) at which about `samples` rays of this view are kept: from the count kept
  // on a coarse grid.
  double Stride(const CoverageView& view, int samples) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Samples of every view, each at its own stride; `stride` (optional) gets the largest.
std::vector<BrdfSample> PredictSamples(const Camera& camera, const SampleSpec& sample,
                                       const std::vector<CoverageView>& views, const CoverageOptions& options,
                                       double* stride = nullptr);

// The reconstruction's classification of every MERL cell from predicted samples taken at `stride`.
CoverageResult ClassifyCoverage(const std::vector<BrdfSample>& samples, double stride, uint64_t views,
                                const CoverageOptions& options);

// PredictSamples then ClassifyCoverage. Throws Error for a mesh sample, no views or bad options.
CoverageResult PredictCoverage(const Camera& camera, const SampleSpec& sample, const std::vector<CoverageView>& views,
                               const CoverageOptions& options);

// The posed measurement photos of a session as views (one per bracket pose: photos with identical poses
// and the same light are one view). `missing` (optional) gets, for each measurement photo without a
// pose or whose light's placement is unknown, "photo FILE: no camera_from_world" or "... light L
// placement unknown".
std::vector<CoverageView> SessionViews(const Session& session, std::vector<std::string>* missing = nullptr);

// Whether each MERL cell's centre lies within `max_theta_deg` (theta_i and theta_e), the tabulation's
// test (reconstruct/merl_table.cc) in closed form: wi.z, wo.z = cos(theta_h) cos(theta_d) -/+
// sin(theta_h) sin(theta_d) cos(phi_d) (core/brdf_coords.cc, FromHalfDiff). kMerlCells bytes, 1 inside.
std::vector<uint8_t> CellsWithinLimit(double max_theta_deg);

// Counts of a domain array (kMerlCells DomainClass bytes, as domain.npy) within the theta limit of
// `options`, per band: for comparing a prediction with a reconstruction's domain.npy.
CoverageResult SummarizeDomain(const std::vector<uint8_t>& domain, const CoverageOptions& options);

}  // namespace ibrdf
