// Colour correction from a colour-chart photo (docs/radiometry.md, "Colour"): the chart's 24 patches
// read through the session's radiometric chain (response, black level, exposure, gain, flat field:
// radiance_image.h), a 3x3 matrix from camera RGB to linear sRGB (or XYZ) fitted by least squares to
// the ColorChecker's published reference values (core/colour.h), written into the session's
// colour_chart block (`ibrdf colour`); the derenderer applies it (derender/colour_correction.h).
// Locating the chart from the user's corner patches, or by trying every orientation of a detected one
// (OpenCV mcc, colour_chart_detector.h), is here.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/session.h"
#include "core/verdict.h"

namespace ibrdf {

struct ColourChartOptions {
  // Each patch is read over a square of this side, in patch pitches, centred on the patch (printed
  // patches fill about 0.85 of the pitch; the rest leaves room for a slightly misplaced corner).
  double patch_fraction = 0.5;
  // A patch whose brightest channel's mean linear signal (normalized file units, before dividing by
  // exposure, in the chart's longest exposure) is below this is too dark to trust (black-level and
  // noise errors) and left out.
  double min_patch_signal = 0.01;
  // A patch with a channel below this fraction of that channel in the chart's brightest usable
  // patch is left out ("black channel"): the sensor cut it at its black level (the cyan patch's red, out
  // of linear sRGB's gamut), so its camera colour is not the linear image of its reflectance, and it
  // would pull every row of the matrix towards the cut.
  double min_channel_fraction = 0.0025;
  // A patch with more than this fraction of clipped (or non-finite) pixels is left out.
  double max_clipped_fraction = 0.0;
  // A patch needs at least this many pixels in its read-out square.
  int min_patch_pixels = 16;
  // The fit needs at least this many usable patches (3 determine the matrix; more average the noise
  // and the chart's own printing tolerance).
  int min_patches = 6;

  bool Check(std::string* why) const;
};

// One patch as read and fitted.
struct ColourPatch {
  int index = 0;                                         // 0 .. 23, chart order
  std::string name;                                      // ColorCheckerPatchNames()[index]
  Eigen::Vector2d center = Eigen::Vector2d::Zero();      // pixel position of its centre
  int pixels = 0;                                        // pixels in its read-out square
  int clipped = 0;                                       // of which clipped or non-finite
  Eigen::Vector3d camera_rgb = Eigen::Vector3d::Zero();  // mean radiance, camera RGB (the session's unit)
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();   // published value in the target space
  Eigen::Vector3d corrected = Eigen::Vector3d::Zero();   // space_from_camera * camera_rgb
  double residual = 0.0;                                 // |corrected - reference| / |reference|
  std::string excluded;                                  // why the fit left it out; empty: used
};

// The chart fit; reads as failure until FitColourChart ran.
struct ColourChartFit {
  bool success = false;
  ColourSpace space = ColourSpace::kLinearSrgb;
  std::string located_by;  // "corner patches (session)" or "OpenCV mcc detector"
  // Camera RGB radiance of the chart -> reflectance in `space` (its overall scale is that of the
  // chart's irradiance; SampleColourMatrix removes it).
  Eigen::Matrix3d space_from_camera = Eigen::Matrix3d::Identity();
  std::vector<ColourPatch> patches;  // all 24, chart order
  int used = 0;                      // patches in the fit
  double rms_residual = 0.0;         // over the used patches
  double max_residual = 0.0;
  std::vector<Verdict> verdicts;     // ColourChartVerdicts, once graded (written into colour.json)

  // "colour: 24 patches (22 used; cyan: clipped, ...), residual 0.4 % RMS, 1.1 % worst"
  std::string BriefReport() const;
  // The fit for colour.json: matrix, space, reference source, every patch.
  nlohmann::json ToJson() const;
};

// The pixel positions of the 24 patch centres, given those of patches 1, 6, 24 and 19 (the chart's
// corner patches, clockwise from the top left): a plane-to-plane homography in the camera's
// undistorted image plane, mapped back through the lens distortion.
std::array<Eigen::Vector2d, kColorCheckerPatches> ColourPatchCenters(const Camera& camera,
                                                                     const std::array<Eigen::Vector2d, 4>& corners);

// Reads the session's chart photos (ColourChartSpec::photos, merged like an exposure bracket), the
// patches at `corners` (ColourPatchCenters), leaves out clipped and too dark patches, and fits the
// matrix. Throws Error naming the manifest for a session without colour_chart, a chart partly out of
// the photo, or too few usable patches (saying which were left out and why).
ColourChartFit FitColourChart(const Session& session, const std::array<Eigen::Vector2d, 4>& corners,
                              const ColourChartOptions& options, const std::string& located_by);

// The fit as `ibrdf colour` runs it: at the session's corner patches (colour_chart.corners) unless
// there are none or `detect` is set; otherwise at the chart OpenCV's mcc finds (colour_chart_detector.h),
// trying each of the 8 ways its box can lie on the chart and keeping the fit of least RMS residual.
// Throws Error naming the manifest for a session without colour_chart, naming the chart's photo when
// no chart is found, and naming the manifest when no orientation gives a usable fit.
ColourChartFit LocateAndFitColourChart(const Session& session, const ColourChartOptions& options, bool detect);

// The chart photo for eyes and for the detector (calibrate/colour_chart_detector.h): its radiance scaled so
// that the 99th percentile of the brightest channel is 0.9, sRGB-encoded, clamped to [0, 1].
Image ColourChartDisplayImage(const Session& session);

// The colour stage as `ibrdf colour` runs it: OUT/session.json (the session with the fitted matrix
// and per-patch fit in its colour_chart block; paths rebased to name the same files), OUT/colour.json
// (ColourChartFit::ToJson) and OUT/chart.png (ColourChartDisplayImage with each patch's read-out
// centre marked), as one folder that appears complete.
void WriteColourStage(const Session& session, const ColourChartFit& fit, const std::string& out_dir, bool overwrite);

// The colour fit's verdicts (docs/verdicts.md): the residual over the used patches (warn over 3 %,
// fail over 10 %: a chart located wrong, or a camera RGB that no 3x3 matrix maps to the chart), and
// the patches used (warn under 18 of 24).
std::vector<Verdict> ColourChartVerdicts(const ColourChartFit& fit);

// Writes the fit into a colour_chart block (matrix and per-patch residuals or exclusions).
void StoreColourFit(const ColourChartFit& fit, ColourChartSpec* chart);

}  // namespace ibrdf
