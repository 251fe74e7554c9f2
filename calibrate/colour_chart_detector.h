// Finding a ColorChecker Classic in a photo with OpenCV contrib's mcc detector
// (cv::mcc::CCheckerDetector), for `ibrdf colour` when the session gives no corner patches. OpenCV's
// types stay in the .cc file. The fit itself is calibrate/colour_chart.h.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/image_io.h"

namespace ibrdf {

struct ColourChartDetection {
  bool found = false;
  // The detected chart's four corners in pixels (docs/conventions.md), in mcc's order.
  std::array<Eigen::Vector2d, 4> box;
  double cost = 0.0;  // mcc's own colour-distance cost of the best chart
  std::string why;    // when not found: what the detector said
};

// Runs mcc (ColorChecker Classic, MCC24, one chart, no neural network) on a display-referred RGB
// image (values in [0, 1], e.g. sRGB-encoded radiance scaled so the chart's white is near 0.9).
ColourChartDetection DetectColorChecker(const Image& display);

// The corner-patch centres (patches 1, 6, 24, 19) a detected box implies, for each of the 8 ways its
// corners can map onto the chart (4 rotations, 2 mirror images): mcc's chart model puts the patch
// centres at (1.5 + 2.75 column, 1.5 + 2.75 row) in a 16.75 x 11.25 box. The caller keeps the one
// whose colour fit is best.
std::vector<std::array<Eigen::Vector2d, 4>> CornerPatchCandidates(const std::array<Eigen::Vector2d, 4>& box);

}  // namespace ibrdf
