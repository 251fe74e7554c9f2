// Tone mapping (report/tone_map.h): the 99th percentile of the luminance lands at 0.8 (sRGB-encoded),
// NaN is magenta, an all-black image keeps scale 1.
#include "report/tone_map.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/radiometry.h"

namespace ibrdf {
namespace {

TEST(ToneMap, ThePercentileLandsAtPointEight) {
  Image linear(10, 10, 3);
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) {
      for (int c = 0; c < 3; ++c) linear.at(x, y, c) = 0.01f * float(y * 10 + x + 1);  // grey, 0.01 to 1
    }
  }
  double scale = 0.0;
  const Image out = ToneMap(linear, &scale);
  // 100 values, rank round(0.99 * 99) = 98: the value 0.99.
  EXPECT_NEAR(scale, 0.8 / 0.99, 1e-6);
  EXPECT_NEAR(out.at(8, 9, 0), LinearToSrgb(0.8), 1e-5);  // the value 0.99
  EXPECT_NEAR(out.at(9, 9, 1), LinearToSrgb(0.8 / 0.99), 1e-5);
  EXPECT_EQ(out.channels, 3);
}

TEST(ToneMap, NanIsMagentaAndBlackKeepsScaleOne) {
  Image linear(2, 1, 3);
  for (int c = 0; c < 3; ++c) linear.at(1, 0, c) = NAN;
  double scale = 0.0;
  const Image out = ToneMap(linear, &scale);
  EXPECT_EQ(scale, 1.0);
  EXPECT_EQ(out.at(0, 0, 0), 0.0f);
  EXPECT_EQ(out.at(1, 0, 0), 1.0f);
  EXPECT_EQ(out.at(1, 0, 1), 0.0f);
  EXPECT_EQ(out.at(1, 0, 2), 1.0f);
}

}  // namespace
}  // namespace ibrdf
