// The sample rendered at its photo's own pixels (report/photo_comparison.h): the samples' own BRDF gives
// back the photo exactly; a model 10 % brighter gives +10 % everywhere; the stride fills blocks; pixels
// without a sample stay black.
#include "report/photo_comparison.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ibrdf {
namespace {

struct Scene {
  Image photo{40, 30, 3};
  std::vector<BrdfSample> samples;
  std::vector<const BrdfSample*> pointers;
};

// Samples every `stride` pixels in a box, f = 0.2, 0.3, 0.4 and a photo of f * (1 + x / 10).
Scene MakeScene(int stride) {
  Scene scene;
  for (int y = 5; y < 25; y += stride) {
    for (int x = 4; x < 36; x += stride) {
      BrdfSample s{};
      s.wi[2] = s.wo[2] = 1.0f;
      s.brdf[0] = 0.2f, s.brdf[1] = 0.3f, s.brdf[2] = 0.4f;
      s.pixel[0] = x, s.pixel[1] = y;
      for (int c = 0; c < 3; ++c) scene.photo.at(x, y, c) = s.brdf[c] * (1.0f + x / 10.0f);
      scene.samples.push_back(s);
    }
  }
  for (const BrdfSample& s : scene.samples) scene.pointers.push_back(&s);
  return scene;
}

TEST(PhotoComparison, OwnBrdfGivesThePhotoAndABrighterModelItsRatio) {
  const Scene scene = MakeScene(1);
  const PixelBox box{0, 0, 39, 29};
  const PhotoRender same = RenderPhotoPixels(scene.photo, box, scene.pointers, "same",
                                             [](auto&, auto&) { return Eigen::Vector3d(0.2, 0.3, 0.4); });
  EXPECT_NEAR(same.median_abs_difference, 0.0, 1e-6);
  EXPECT_NEAR(same.linear.at(10, 10, 1), scene.photo.at(10, 10, 1), 1e-6);
  const PhotoRender brighter = RenderPhotoPixels(scene.photo, box, scene.pointers, "brighter",
                                                 [](auto&, auto&) { return Eigen::Vector3d(0.22, 0.33, 0.44); });
  EXPECT_NEAR(brighter.median_abs_difference, 0.1, 1e-5);
  EXPECT_NEAR(brighter.difference.at(20, 12, 0), 0.1, 1e-5);
  // Outside the samples: black render, no difference.
  EXPECT_EQ(brighter.linear.at(1, 1, 0), 0.0f);
  EXPECT_TRUE(std::isnan(brighter.difference.at(1, 1, 0)));
  // A model without a value: NaN (drawn magenta), not a number.
  const PhotoRender none = RenderPhotoPixels(scene.photo, box, scene.pointers, "none",
                                             [](auto&, auto&) { return Eigen::Vector3d(-1, -1, -1); });
  EXPECT_TRUE(std::isnan(none.linear.at(10, 10, 0)));
}

// A channel the sample did not measure (its `valid` flag 0: clipped, under the floor) is left out of
// the difference: a photo clipped in red, whose samples' red is flagged, still compares equal to the
// samples' own BRDF in green and blue; with no channel measured there is no difference at all.
TEST(PhotoComparison, UnmeasuredChannelsAreLeftOut) {
  Scene scene = MakeScene(1);
  for (BrdfSample& s : scene.samples) {
    scene.photo.at(int(s.pixel[0]), int(s.pixel[1]), 0) = 0.05f;  // red clipped low: no longer f * E
    s.valid[0] = 0;
  }
  const PixelBox box{0, 0, 39, 29};
  const PhotoRender same = RenderPhotoPixels(scene.photo, box, scene.pointers, "same",
                                             [](auto&, auto&) { return Eigen::Vector3d(0.2, 0.3, 0.4); });
  EXPECT_NEAR(same.median_abs_difference, 0.0, 1e-6);
  EXPECT_NEAR(same.difference.at(20, 12, 0), 0.0, 1e-6);
  // A model wrong only in the unmeasured channel makes no difference; one 10 % brighter in green and
  // blue shows +10 %.
  const PhotoRender red_off = RenderPhotoPixels(scene.photo, box, scene.pointers, "red",
                                                [](auto&, auto&) { return Eigen::Vector3d(0.9, 0.3, 0.4); });
  EXPECT_NEAR(red_off.median_abs_difference, 0.0, 1e-6);
  const PhotoRender brighter = RenderPhotoPixels(scene.photo, box, scene.pointers, "brighter",
                                                 [](auto&, auto&) { return Eigen::Vector3d(0.2, 0.33, 0.44); });
  EXPECT_NEAR(brighter.median_abs_difference, 0.1, 1e-5);
  for (BrdfSample& s : scene.samples) s.valid[1] = s.valid[2] = 0;
  const PhotoRender unmeasured = RenderPhotoPixels(scene.photo, box, scene.pointers, "same",
                                                   [](auto&, auto&) { return Eigen::Vector3d(0.2, 0.3, 0.4); });
  EXPECT_TRUE(std::isnan(unmeasured.difference.at(20, 12, 0)));
  EXPECT_TRUE(std::isnan(unmeasured.median_abs_difference));
}

TEST(PhotoComparison, StrideIsFoundAndFillsBlocks) {
  const Scene scene = MakeScene(3);
  EXPECT_EQ(SampleStride(scene.pointers), 3);
  const PhotoRender render = RenderPhotoPixels(scene.photo, PixelBox{0, 0, 39, 29}, scene.pointers, "m",
                                               [](auto&, auto&) { return Eigen::Vector3d(0.4, 0.6, 0.8); });
  // The sample at (4, 5) fills x 3..5, y 4..6 with its value: twice the photo at (4, 5).
  EXPECT_NEAR(render.linear.at(3, 4, 0), 2 * scene.photo.at(4, 5, 0), 1e-6);
  EXPECT_NEAR(render.linear.at(5, 6, 0), 2 * scene.photo.at(4, 5, 0), 1e-6);
  EXPECT_NEAR(render.difference.at(5, 6, 0), 1.0, 1e-5);
  const std::vector<const BrdfSample*> one = {scene.pointers.front()};
  EXPECT_EQ(SampleStride(one), 1);
}

}  // namespace
}  // namespace ibrdf
