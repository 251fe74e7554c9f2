// ArUco markers: dictionaries by name, and detection with edge-fitted corners on a rendered marker.
#include "align/markers.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/camera.h"
#include "core/error.h"

namespace ibrdf {
namespace {

TEST(MarkerDictionary, KnownAndUnknownNames) {
  const MarkerDictionary dictionary("DICT_4X4_50");
  EXPECT_EQ(dictionary.size(), 50);
  EXPECT_EQ(dictionary.modules(), 6);
  const std::vector<bool> cells = dictionary.Modules(3);
  ASSERT_EQ(cells.size(), 36u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_FALSE(cells[k]);       // top border is black
    EXPECT_FALSE(cells[30 + k]);  // bottom border
  }
  EXPECT_THROW(MarkerDictionary("DICT_9X9_7"), Error);
}

// Renders marker `id` rotated by `angle` about its centre with 16 x 16 supersampling (edges exact to
// 1/32 pixel) on a white card.
Image RenderMarker(const MarkerDictionary& dictionary, int id, const Eigen::Vector2d& center, double side, double angle,
                   std::array<Eigen::Vector2d, 4>* corners) {
  Image image(240, 200, 1);
  const std::vector<bool> cells = dictionary.Modules(id);
  const int n = dictionary.modules();
  const Eigen::Vector2d x_axis(std::cos(angle), std::sin(angle)), y_axis(-std::sin(angle), std::cos(angle));
  const Eigen::Vector2d top_left = center - 0.5 * side * (x_axis + y_axis);
  *corners = {top_left, top_left + side * x_axis, top_left + side * (x_axis + y_axis), top_left + side * y_axis};
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      double sum = 0.0;
      for (int sy = 0; sy < 16; ++sy) {
        for (int sx = 0; sx < 16; ++sx) {
          const Eigen::Vector2d p(x + (sx + 0.5) / 16, y + (sy + 0.5) / 16);
          const double u = (p - top_left).dot(x_axis) / side, v = (p - top_left).dot(y_axis) / side;
          bool white = true;
          if (u >= 0 && u < 1 && v >= 0 && v < 1) white = cells[int(v * n) * n + int(u * n)];
          sum += white ? 0.8 : 0.03;
        }
      }
      image.at(x, y, 0) = float(sum / 256);
    }
  }
  return image;
}

TEST(DetectMarkers, FindsTheIdAndEdgeFittedCornersAreAccurate) {
  const MarkerDictionary dictionary("DICT_4X4_50");
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 240, 200, {500, 500, 120, 100});
  for (double angle : {0.0, 0.3, 1.1}) {
    std::array<Eigen::Vector2d, 4> truth;
    const Image image = RenderMarker(dictionary, 7, Eigen::Vector2d(121.3, 98.6), 90.0, angle, &truth);
    std::vector<MarkerDetection> detections = DetectMarkers(image, dictionary);
    ASSERT_EQ(detections.size(), 1u) << "angle " << angle;
    EXPECT_EQ(detections[0].id, 7);
    RefineMarkerCorners(image, camera, &detections);
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT((detections[0].corners[k] - truth[k]).norm(), 0.05)
          << "angle " << angle << " corner " << k << " at " << detections[0].corners[k].transpose() << " truth "
          << truth[k].transpose();
    }
  }
}

TEST(DetectMarkers, BlankImageHasNoMarkersAndNaNIsHarmless) {
  const MarkerDictionary dictionary("DICT_4X4_50");
  Image image(100, 80, 3);
  for (float& v : image.pixels) v = 0.5f;
  image.at(10, 10, 0) = NAN;
  EXPECT_TRUE(DetectMarkers(image, dictionary).empty());
}

}  // namespace
}  // namespace ibrdf
