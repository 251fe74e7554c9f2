// The camera's response curve measured from exposure brackets of a static scene (docs/radiometry.md,
// "Measuring the response"): Debevec and Malik 1997 through OpenCV's photo module
// (cv::createCalibrateDebevec), with cv::createCalibrateRobertson as an independent cross-check. Every
// bracket of the session (the photos of one pose under one light at several exposures: ExposureGroups,
// radiometry/radiance_image.h) is calibrated on its own from pixels chosen across its range of values;
// the curves of all brackets and channels are combined level by level (their median), and their
// spread is the curve's uncertainty. `ibrdf response` writes the result into the session as
// radiometry.response {"table", "uncertainty"} and refuses brackets that cannot constrain it.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/radiometry.h"
#include "core/session.h"
#include "core/verdict.h"

namespace ibrdf {

struct ResponseCalibrationOptions {
  // Pixels chosen per bracket, spread evenly over the bracket's range of values (the points whose
  // values across the exposures Debevec's linear system ties together). The system is solved densely:
  // its cost grows with the square of this.
  int pixels_per_bracket = 400;
  // Debevec's smoothness weight lambda (the curve's second difference against the data terms). OpenCV's
  // default 10 follows the sensor noise into the curve: on noisy 12-bit brackets of a toe-and-shoulder
  // curve the shape error was 6.7 % at 10, 2.4 % at 30, 1.6 % at 50 and 3.7 % at 100 (12 poses).
  double smoothness = 50.0;
  // At most this many brackets are calibrated (chosen evenly among the session's).
  int max_brackets = 12;

  bool Check(std::string* why) const;
};

// One exposure bracket as the calibration saw it.
struct ResponseBracket {
  std::string first_photo;    // the bracket's first photo file, as the manifest names it
  int exposures = 0;          // distinct exposures (exposure_s x gain)
  double span_ev = 0.0;       // log2 of the longest over the shortest exposure
  int pixels = 0;             // pixels that went into its system
  std::string left_out;       // why it was not used ("" when used)
};

struct ResponseCalibration {
  // kTable with 256 entries (one per 8-bit level): the linear value at file value i / 255, scaled so
  // that full scale (file value 1) is 1 and with file value 0 at 0; `uncertainty` holds each entry's
  // relative standard error. The curve includes any black level (a black offset is part of the
  // mapping from light to file value that the brackets measure).
  Response response;
  int brackets_used = 0;
  int pixels_used = 0;
  double span_ev = 0.0;  // the largest span of a used bracket
  // The 8-bit levels the data constrain: a level is constrained when two or more curves (a bracket's
  // channel each) have at least kMinLevelHits usable exposures of their chosen pixels there. Outside
  // [lowest_level, highest_level] the curve is the smoothness term's extrapolation (said in the outputs).
  int lowest_level = 0, highest_level = 0;
  double level_coverage = 0.0;        // fraction of the levels of 5-95 % of full scale that are constrained
  double median_uncertainty = 0.0;    // median relative standard error over those constrained levels
  double max_uncertainty = 0.0;       // the largest there
  double channel_spread = 0.0;        // largest relative difference of one channel's curve from the combined one
  double robertson_difference = 0.0;  // largest relative difference of Robertson's curve from Debevec's
  bool monotonic = true;              // the combined curve rises over the constrained levels from 5 % up
  std::array<std::vector<double>, 3> channel_tables;  // each channel's curve (median over brackets), as the table
  std::vector<ResponseBracket> brackets;
  std::vector<Verdict> verdicts;

  static constexpr int kMinLevelHits = 3;

  // {"format": "ibrdf-response", ...}: the table, its uncertainty, the figures above, the brackets and
  // the verdicts.
  nlohmann::json ToJson() const;
  // "response: 256-level table from 6 brackets (2400 pixels, 6.0 EV), levels 3-252 constrained, ..."
  std::string BriefReport() const;
};

// Calibrates the response from the session's measurement brackets (photos read as file values, 8-bit
// levels). Throws Error naming the session when no bracket has two distinct exposures or a photo
// cannot be read; everything else is a figure the verdicts judge.
ResponseCalibration CalibrateResponse(const Session& session, const ResponseCalibrationOptions& options);

// response.brackets, response.span, response.coverage, response.uncertainty, response.monotonic,
// response.channels and response.methods (docs/verdicts.md).
std::vector<Verdict> ResponseVerdicts(const ResponseCalibration& calibration);

// The session with the measured response (black level 0: the curve includes it), marked as having
// had its response measured; written to OUT/session.json with OUT/response.json beside it, whole or not
// at all.
void WriteResponseStage(const Session& session, const ResponseCalibration& calibration, const std::string& out_dir,
                        bool overwrite);

}  // namespace ibrdf
