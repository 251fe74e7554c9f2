// synth/photo_png.h: synth's photos written with libpng hold the same pixels and EXIF as through
// OpenImageIO (core WriteImage), decoded by both ibrdf's libpng reader and OpenImageIO.
#include "synth/photo_png.h"

#include <cmath>
#include <filesystem>
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

// Every level of `bits` (then random levels) as synth's sensor stores them: double(k) / (2^bits - 1)
// rounded to float.
Image QuantizedImage(int width, int height, int channels, int bits, uint32_t seed) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  const double levels = std::ldexp(1.0, bits) - 1.0;
  std::mt19937 random(seed);
  std::uniform_int_distribution<uint32_t> level(0, uint32_t(levels));
  image.pixels.resize(size_t(width) * height * channels);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const uint32_t k = i <= size_t(levels) ? uint32_t(i) : level(random);
    image.pixels[i] = static_cast<float>(double(k) / levels);
  }
  return image;
}

// Writes `image` both ways and expects the same decoded pixels (libpng reader and OpenImageIO).
void ExpectSamePixels(const Image& image, PixelFormat format, const ScratchDir& dir) {
  const std::string ours = dir / "ours.png", theirs = dir / "theirs.png";
  ASSERT_TRUE(IsPlainPhotoPng(ours, image, format));
  WritePhotoPng(ours, image, format);
  WriteImage(theirs, image, format);
  const Image a = ReadImage(ours), b = ReadImage(theirs);
  ASSERT_EQ(a.width, image.width);
  ASSERT_EQ(a.height, image.height);
  ASSERT_EQ(a.channels, image.channels);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) differing += a.pixels[i] != b.pixels[i];
  EXPECT_EQ(differing, 0u);
  Image through_oiio;
  ReadImageThroughOpenImageIO(ours, &through_oiio);
  EXPECT_EQ(through_oiio.pixels, b.pixels);
}

TEST(PhotoPng, SixteenBitRgbHasOpenImageIOsPixels) {
  ScratchDir dir;
  ExpectSamePixels(QuantizedImage(301, 257, 3, 16, 1), PixelFormat::kUint16, dir);  // all 65536 levels
}

TEST(PhotoPng, SixteenBitGreyHasOpenImageIOsPixels) {
  ScratchDir dir;
  ExpectSamePixels(QuantizedImage(256, 257, 1, 16, 2), PixelFormat::kUint16, dir);
}

TEST(PhotoPng, EightBitRgbAndGreyHaveOpenImageIOsPixels) {
  ScratchDir dir;
  ExpectSamePixels(QuantizedImage(40, 30, 3, 8, 3), PixelFormat::kUint8, dir);
  ExpectSamePixels(QuantizedImage(40, 30, 1, 8, 4), PixelFormat::kUint8, dir);
}

TEST(PhotoPng, TwelveBitSignalsStoredAsSixteenBitsHaveOpenImageIOsPixels) {
  // The demo's camera: 12-bit levels k / 4095 in a 16-bit file.
  ScratchDir dir;
  ExpectSamePixels(QuantizedImage(200, 100, 3, 12, 5), PixelFormat::kUint16, dir);
}

TEST(PhotoPng, ClampsOutOfRangeValuesAndNaN) {
  ScratchDir dir;
  Image image;
  image.width = 4;
  image.height = 1;
  image.channels = 1;
  image.pixels = {-0.5f, 1.5f, std::numeric_limits<float>::quiet_NaN(), 0.5f};
  WritePhotoPng(dir / "clamped.png", image, PixelFormat::kUint16);
  const Image back = ReadImage(dir / "clamped.png");
  ASSERT_EQ(back.pixels.size(), 4u);
  EXPECT_EQ(back.pixels[0], 0.0f);
  EXPECT_EQ(back.pixels[1], 1.0f);
  EXPECT_EQ(back.pixels[2], 0.0f);
  EXPECT_EQ(back.pixels[3], float(32768) * (1.0f / 65535.0f));  // 32767.5 rounds up
}

TEST(PhotoPng, WritesTheExifThatWriteImageWrites) {
  ScratchDir dir;
  PhotoMetadata metadata;
  metadata.exposure_s = 1.0 / 125.0;
  metadata.iso = 200;
  metadata.f_number = 8.0;
  metadata.focal_length_mm = 35.0;
  metadata.focal_length_35mm = 52;
  metadata.pixels_per_mm = 222.2;
  metadata.make = "ibrdf";
  metadata.model = "synth";
  metadata.date_time = "2026:11:30 12:00:10";
  const Image image = QuantizedImage(16, 8, 3, 12, 6);
  WritePhotoPng(dir / "ours.png", image, PixelFormat::kUint16, &metadata);
  WriteImage(dir / "theirs.png", image, PixelFormat::kUint16, &metadata);
  const PhotoMetadata a = ReadPhotoMetadata(dir / "ours.png"), b = ReadPhotoMetadata(dir / "theirs.png");
  ASSERT_TRUE(a.exposure_s.has_value());
  EXPECT_EQ(a.exposure_s, b.exposure_s);
  EXPECT_EQ(a.iso, b.iso);
  EXPECT_EQ(a.f_number, b.f_number);
  EXPECT_EQ(a.focal_length_mm, b.focal_length_mm);
  EXPECT_EQ(a.focal_length_35mm, b.focal_length_35mm);
  EXPECT_EQ(a.pixels_per_mm, b.pixels_per_mm);
  EXPECT_EQ(a.make, "ibrdf");
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.date_time, b.date_time);
  EXPECT_EQ(a.bits, 16);
  EXPECT_EQ(a.channels, 3);
}

TEST(PhotoPng, OtherFilesGoThroughWriteImage) {
  ScratchDir dir;
  Image image = QuantizedImage(8, 4, 3, 16, 7);
  EXPECT_FALSE(IsPlainPhotoPng(dir / "a.tif", image, PixelFormat::kUint16));
  EXPECT_FALSE(IsPlainPhotoPng(dir / "a.png", image, PixelFormat::kFloat));
  WritePhotoPng(dir / "a.tif", image, PixelFormat::kUint16);
  WriteImage(dir / "b.tif", image, PixelFormat::kUint16);
  const Image a = ReadImage(dir / "a.tif");
  EXPECT_EQ(a.channels, 3);
  EXPECT_EQ(a.pixels, ReadImage(dir / "b.tif").pixels);
}

TEST(PhotoPng, AnUnwritableFolderIsAnErrorNamingTheFile) {
  ScratchDir dir;
  const std::string path = dir / "missing/photo.png";
  const std::string error = ErrorOf([&] { WritePhotoPng(path, QuantizedImage(4, 4, 3, 16, 8), PixelFormat::kUint16); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace ibrdf
