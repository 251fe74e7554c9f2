#include "calibrate/colour_chart_detector.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>

namespace ibrdf {

ColourChartDetection DetectColorChecker(const Image& display) {
  ColourChartDetection detection;
  cv::Mat bgr(display.height, display.width, CV_8UC3);
  for (int y = 0; y < display.height; ++y) {
    for (int x = 0; x < display.width; ++x) {
      cv::Vec3b& out = bgr.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        const float v = display.at(x, y, display.channels == 1 ? 0 : c);
        out[2 - c] = static_cast<uint8_t>(std::clamp(std::lround(255.0f * v), 0L, 255L));
      }
    }
  }
  cv::Ptr<cv::mcc::CCheckerDetector> detector = cv::mcc::CCheckerDetector::create();
  cv::Ptr<cv::mcc::DetectorParameters> parameters = cv::mcc::DetectorParameters::create();
  if (!detector->process(bgr, cv::mcc::MCC24, 1, false, parameters)) {
    detection.why = "OpenCV's mcc detector found no ColorChecker Classic in the photo";
    return detection;
  }
  const cv::Ptr<cv::mcc::CChecker> checker = detector->getBestColorChecker();
  const std::vector<cv::Point2f> box = checker ? checker->getBox() : std::vector<cv::Point2f>();
  if (box.size() != 4) {
    detection.why = "OpenCV's mcc detector returned a chart without four corners";
    return detection;
  }
  for (int k = 0; k < 4; ++k) detection.box[k] = Eigen::Vector2d(box[k].x, box[k].y);
  detection.cost = checker->getCost();
  detection.found = true;
  return detection;
}

std::vector<std::array<Eigen::Vector2d, 4>> CornerPatchCandidates(const std::array<Eigen::Vector2d, 4>& box) {
  // mcc's chart model: the box (0, 0), (width, 0), (width, height), (0, height), in its corner order.
  const double width = 16.75, height = 11.25;
  std::vector<std::array<Eigen::Vector2d, 4>> candidates;
  for (int mirror = 0; mirror < 2; ++mirror) {
    for (int shift = 0; shift < 4; ++shift) {
      // Box corner k is model corner order[k].
      std::array<Eigen::Vector2d, 4> image;
      for (int k = 0; k < 4; ++k) {
        const int m = mirror ? (4 - k + shift) % 4 : (k + shift) % 4;
        image[m] = box[k];
      }
      // Bilinear in the box (a homography would be exact; the patches' read-out squares allow for the
      // difference at the chart's small perspective).
      auto at = [&](double u, double v) {
        const double s = u / width, t = v / height;
        return Eigen::Vector2d((1 - s) * (1 - t) * image[0] + s * (1 - t) * image[1] + s * t * image[2] +
                               (1 - s) * t * image[3]);
      };
      const double c0 = 1.5, c5 = 1.5 + 2.75 * 5, r0 = 1.5, r3 = 1.5 + 2.75 * 3;
      candidates.push_back({at(c0, r0), at(c5, r0), at(c5, r3), at(c0, r3)});
    }
  }
  return candidates;
}

}  // namespace ibrdf
