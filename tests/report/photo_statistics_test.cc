// Per-photo statistics (report/photo_statistics.h): counts, pixel boxes and phase angles, the photo of
// median phase chosen by default, a requested photo without samples refused naming --photo.
#include "report/photo_statistics.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

// A sample of photo `image` at pixel (x, y) whose wi and wo are `phase` radians apart.
BrdfSample Sample(uint32_t image, int x, int y, double phase) {
  BrdfSample s{};
  s.image = image;
  s.pixel[0] = x;
  s.pixel[1] = y;
  s.wi[0] = 0.0;
  s.wi[1] = 0.0;
  s.wi[2] = 1.0;
  s.wo[0] = std::sin(phase);
  s.wo[1] = 0.0;
  s.wo[2] = std::cos(phase);
  return s;
}

TEST(PhotoStatistics, CountsBoxesAndTheMedianPhotoIsChosen) {
  const std::vector<BrdfSample> samples = {Sample(0, 5, 7, 0.1), Sample(0, 9, 3, 0.1), Sample(2, 1, 1, 0.5),
                                           Sample(4, 2, 2, 0.9), Sample(4, 3, 3, 0.9)};
  const std::map<uint32_t, PhotoStats> photos = CollectPhotoStats(samples);
  ASSERT_EQ(photos.size(), 3u);
  const PhotoStats& first = photos.at(0);
  EXPECT_EQ(first.count, 2u);
  EXPECT_EQ(first.x0, 5);
  EXPECT_EQ(first.y0, 3);
  EXPECT_EQ(first.x1, 9);
  EXPECT_EQ(first.y1, 7);
  ASSERT_EQ(first.phase.size(), 2u);
  EXPECT_NEAR(first.phase[0], 0.1, 1e-6);
  const ChosenPhoto chosen = ChoosePhoto(photos, -1);
  EXPECT_EQ(chosen.photo, 2u);
  EXPECT_NEAR(chosen.phase, 0.5, 1e-6);
  EXPECT_EQ(ChoosePhoto(photos, 4).photo, 4u);
}

TEST(PhotoStatistics, ARequestedPhotoWithoutSamplesIsAnError) {
  const std::map<uint32_t, PhotoStats> photos = CollectPhotoStats({Sample(0, 0, 0, 0.2)});
  std::string message;
  try {
    ChoosePhoto(photos, 3);
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_EQ(message, "--photo: photo 3 has no samples");
}

}  // namespace
}  // namespace ibrdf
