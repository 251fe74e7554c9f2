// report/report_png.h: the report's PNGs written with libpng are byte for byte those core WriteImage
// writes through OpenImageIO (so the report's files did not change when it stopped loading OpenImageIO).
#include "report/report_png.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/image_io.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ErrorOf;
using testing::ScratchDir;

std::string Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Every 8-bit level, values half a level either side of each, then random values in [0, 1] (most
// not on a level: the rounding of every value matters).
Image TestImage(int width, int height, int channels, uint32_t seed) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.resize(size_t(width) * height * channels);
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    if (i < 256) {
      image.pixels[i] = float(i) / 255.0f;
    } else if (i < 768) {
      image.pixels[i] = (float(i / 2 - 128) + (i % 2 ? 0.5f : -0.5f)) / 255.0f;
    } else {
      image.pixels[i] = uniform(random);
    }
  }
  return image;
}

void ExpectSameBytes(const Image& image, const ScratchDir& dir) {
  WriteReportPng(dir / "ours.png", image);
  WriteImage(dir / "theirs.png", image, PixelFormat::kUint8);
  const std::string ours = Bytes(dir / "ours.png"), theirs = Bytes(dir / "theirs.png");
  ASSERT_GT(theirs.size(), 50u);
  EXPECT_TRUE(ours == theirs) << "sizes " << ours.size() << " and " << theirs.size();
}

TEST(ReportPng, RgbIsByteIdenticalToWriteImage) {
  ScratchDir dir;
  ExpectSameBytes(TestImage(640, 480, 3, 1), dir);
  ExpectSameBytes(TestImage(200, 428, 3, 2), dir);  // the demo's photo crop
}

TEST(ReportPng, GreyIsByteIdenticalToWriteImage) {
  ScratchDir dir;
  ExpectSameBytes(TestImage(257, 129, 1, 3), dir);
}

TEST(ReportPng, SmoothImagesAreByteIdenticalToWriteImage) {
  // A rendered sphere's smooth gradients (other row filters win than on noise) with a dark background.
  ScratchDir dir;
  Image image = TestImage(256, 256, 3, 4);
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      const double r2 = ((x - 128.0) * (x - 128.0) + (y - 128.0) * (y - 128.0)) / (120.0 * 120.0);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = r2 < 1.0 ? float((1.0 - r2) * (0.3 + 0.3 * c)) : 0.0f;
    }
  }
  ExpectSameBytes(image, dir);
}

TEST(ReportPng, OutOfRangeAndNaNAreClampedAsWriteImageDoes) {
  ScratchDir dir;
  Image image = TestImage(16, 16, 3, 5);
  image.pixels[0] = -1.0f;
  image.pixels[1] = 2.0f;
  image.pixels[2] = std::numeric_limits<float>::infinity();
  ExpectSameBytes(image, dir);
  image.pixels[3] = std::numeric_limits<float>::quiet_NaN();
  WriteReportPng(dir / "nan.png", image);
  EXPECT_EQ(ReadImage(dir / "nan.png").pixels[3], 0.0f);
}

TEST(ReportPng, OtherChannelCountsGoThroughWriteImage) {
  ScratchDir dir;
  ExpectSameBytes(TestImage(20, 10, 4, 6), dir);
  ExpectSameBytes(TestImage(20, 10, 2, 7), dir);
}

TEST(ReportPng, AnUnwritableFolderIsAnErrorNamingTheFile) {
  ScratchDir dir;
  const std::string path = dir / "missing/photo.png";
  const std::string error = ErrorOf([&] { WriteReportPng(path, TestImage(4, 4, 3, 8)); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace ibrdf
