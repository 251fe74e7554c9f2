// The colour chart's matrix applied to the samples (docs/radiometry.md, "Colour"): `ibrdf colour`
// fits it into the session's colour_chart block (calibrate/colour_chart.h); the derenderer turns it,
// per light, into the matrix that takes a sample's camera-RGB BRDF to the chart's space, and reports
// it in the samples' sidecar and the log.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/sample_file.h"
#include "core/session.h"

namespace ibrdf {

// The matrix the derenderer applies to a sample's camera-RGB BRDF under a light of camera-RGB
// intensity `light_intensity` (the session's, after any white-reference calibration):
//   C = diag(w / (A I)) A diag(I),  A = linear-sRGB-from-camera, w = (1, 1, 1);  XYZ: XyzFromLinearSrgb C.
// f_camera is L / (I cos / r^2) per channel; A diag(I) f_camera is then the BRDF in linear sRGB up to
// the light's brightness, which dividing by A I (the light's own colour in sRGB: grey for a light whose
// colour the chart saw, whatever its tint) removes: a white diffuser reads 1/pi in every channel.
Eigen::Matrix3d SampleColourMatrix(const ColourChartSpec& chart, const Eigen::Vector3d& light_intensity);

// What ApplyColourCorrection did to the samples' channels (each count over the samples it was given).
struct ColourCorrectionCounts {
  // Channels (R, G, B) that came out of the matrix measured but negative or not finite (a noisy dark
  // channel, or a matrix with negative terms over a saturated hue): marked unmeasured (valid 0) with
  // brdf and sigma 0, so no file ever holds a value its readers refuse.
  std::array<uint64_t, 3> negative{};
  // Samples left with no measured channel: removed.
  uint64_t dropped = 0;
};

// Applies SampleColourMatrix of each sample's photo's light to its brdf and (propagated, channels
// taken as independent) sigma; returns the matrices used, one per light. Nothing without a fitted
// colour_chart. A corrected channel is measured only when every camera channel it mixes is, and when its
// value is finite and not negative; an unmeasured channel's brdf is clamped to 0 or more (it is no
// measurement, but the file's readers refuse negative values). Samples left with no measured channel are
// removed. `counts` (optional) gets the channels marked unmeasured for their sign and the samples removed.
// Throws Error naming the manifest for a colour_chart without a matrix (run `ibrdf colour`).
std::vector<Eigen::Matrix3d> ApplyColourCorrection(const Session& session, std::vector<BrdfSample>* samples,
                                                   ColourCorrectionCounts* counts = nullptr);

// The matrices ApplyColourCorrection applies, one per light (empty without a colour_chart); throws as it
// does. Known before any photo is derendered, so the derenderer corrects each photo's samples as they come.
std::vector<Eigen::Matrix3d> SampleColourMatrices(const Session& session);

// ApplyColourCorrection with `matrices` (SampleColourMatrices of the session) on any run of samples, one
// photo's say: `counts` gets this run's negative channels and removed samples added. Nothing for empty
// `matrices`. Each sample is corrected on its own, so applying it run by run equals applying it once.
void ApplyColourMatrices(const Session& session, const std::vector<Eigen::Matrix3d>& matrices,
                         std::vector<BrdfSample>* samples, ColourCorrectionCounts* counts);

// The sidecar's "colour" entry: space, reference source, the chart's matrix and per-patch fit, and the
// matrices applied per light. Null without a colour_chart.
nlohmann::json ColourSidecar(const Session& session, const std::vector<Eigen::Matrix3d>& applied);

// For the log: the space, the chart's matrix, each patch's residual (or why it was left out) and the
// matrices applied per light, over several lines.
std::string ColourCorrectionReport(const Session& session, const std::vector<Eigen::Matrix3d>& applied);

// The sidecar's "colour_space" line for a session (camera RGB, or the chart's space).
std::string ColourSpaceDescription(const Session& session);

}  // namespace ibrdf
