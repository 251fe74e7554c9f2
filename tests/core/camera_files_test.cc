// Camera files: EXIF written with a photo reads back (PNG, EXR, TIFF); a DNG
// of known raw values decodes to (raw - black) / (white - black) per channel within quantization, the
// black and white levels taken from the file; float photos have no saturation unless the session
// states one, integer photos clip at full scale.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_io.h"
#include "core/session.h"
#include "radiometry/linear_image.h"
#include "tests/core/test_dng.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

PhotoMetadata ExampleMetadata() {
  PhotoMetadata m;
  m.exposure_s = 1.0 / 125.0;
  m.iso = 400.0;
  m.f_number = 8.0;
  m.focal_length_mm = 50.0;
  m.focal_length_35mm = 75.0;
  m.pixels_per_mm = 1.0 / 0.0045;
  m.make = "ibrdf";
  m.model = "test camera";
  m.date_time = "2026:01:02 03:04:05";
  return m;
}

// Every EXIF field survives a write and a read, in each format synth and cameras use.
TEST(CameraFiles, ExifRoundTrips) {
  ScratchDir dir;
  Image image(16, 12, 3);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = float(i % 97) / 97.0f;
  const PhotoMetadata m = ExampleMetadata();
  for (const auto& [name, format] : std::vector<std::pair<std::string, PixelFormat>>{
           {"a.png", PixelFormat::kUint16}, {"b.png", PixelFormat::kUint8}, {"c.exr", PixelFormat::kFloat}}) {
    const std::string path = dir / name;
    WriteImage(path, image, format, &m);
    const PhotoMetadata back = ReadPhotoMetadata(path);
    ASSERT_TRUE(back.exposure_s) << name;
    EXPECT_NEAR(*back.exposure_s, 1.0 / 125.0, 1e-6) << name;
    ASSERT_TRUE(back.iso) << name;
    EXPECT_EQ(*back.iso, 400.0) << name;
    ASSERT_TRUE(back.f_number && back.focal_length_mm && back.focal_length_35mm && back.pixels_per_mm) << name;
    EXPECT_NEAR(*back.f_number, 8.0, 1e-6);
    EXPECT_NEAR(*back.focal_length_mm, 50.0, 1e-4);
    EXPECT_EQ(*back.focal_length_35mm, 75.0);
    EXPECT_NEAR(*back.pixels_per_mm, 1.0 / 0.0045, 1e-2);
    EXPECT_EQ(back.make, "ibrdf");
    EXPECT_EQ(back.model, "test camera");
    EXPECT_EQ(back.date_time, "2026:01:02 03:04:05");
    EXPECT_EQ(back.width, 16);
    EXPECT_EQ(back.height, 12);
    EXPECT_EQ(back.floating_point, format == PixelFormat::kFloat) << name;
    EXPECT_EQ(back.bits, format == PixelFormat::kFloat ? 0 : format == PixelFormat::kUint8 ? 8 : 16) << name;
    // The pixels are unchanged by the EXIF chunk.
    const Image pixels = ReadImage(path);
    const double step = format == PixelFormat::kUint8 ? 1.0 / 255 : format == PixelFormat::kUint16 ? 1.0 / 65535 : 0.0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      ASSERT_NEAR(pixels.pixels[i], image.pixels[i], 0.5 * step + 1e-7) << name << " value " << i;
    }
  }
  // A photo without metadata has none.
  WriteImage(dir / "plain.png", image, PixelFormat::kUint16);
  const PhotoMetadata plain = ReadPhotoMetadata(dir / "plain.png");
  EXPECT_FALSE(plain.exposure_s);
  EXPECT_FALSE(plain.iso);
}

// The raw values of the test mosaic: per 16 x 16 block a colour (r, g, b) of raw values, so the
// interior of each block is uniform after demosaicing; the last block is at the white level.
struct Block {
  int x0, y0;
  uint16_t raw[3];
};

std::vector<uint16_t> Mosaic(int width, int height, const std::vector<Block>& blocks) {
  std::vector<uint16_t> mosaic(size_t(width) * height, 0);
  for (const Block& block : blocks) {
    for (int y = block.y0; y < block.y0 + 16; ++y) {
      for (int x = block.x0; x < block.x0 + 16; ++x)
        mosaic[size_t(y) * width + x] = block.raw[testing::BayerChannel(x, y)];
    }
  }
  return mosaic;
}

// The known linear values: black and white levels from the DNG's tags, no white balance, no colour
// matrix, within LibRaw's 16-bit output quantization; the same scene at other levels decodes the same.
TEST(CameraFiles, DngDecodesToKnownLinearValues) {
  ScratchDir dir;
  const int width = 64, height = 48;
  for (const auto& [black, white] : std::vector<std::pair<int, int>>{{256, 4095}, {1024, 16383}, {0, 65535}}) {
    // The same linear values at each level pair: raw = black + value x (white - black), rounded.
    const double values[4][3] = {{0.05, 0.2, 0.6}, {0.5, 0.5, 0.5}, {0.9, 0.01, 0.3}, {1.0, 1.0, 1.0}};
    std::vector<Block> blocks;
    for (int k = 0; k < 4; ++k) {
      Block block{16 * k, 16, {}};
      for (int c = 0; c < 3; ++c) block.raw[c] = uint16_t(std::lround(black + values[k][c] * (white - black)));
      blocks.push_back(block);
    }
    const std::string path = dir / ("mosaic-" + std::to_string(white) + ".dng");
    ASSERT_TRUE(testing::WriteTestDng(path, width, height, Mosaic(width, height, blocks), black, white));
    const PhotoMetadata metadata = ReadPhotoMetadata(path);
    EXPECT_TRUE(metadata.raw);
    EXPECT_FALSE(metadata.floating_point);
    const Image image = ReadImage(path);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.channels, 3);
    EXPECT_FALSE(image.floating_point);
    // Within one raw step (the rounding above) plus LibRaw's 16-bit output step.
    const double tolerance = 0.5 / (white - black) + 1.0 / 65535;
    for (int k = 0; k < 4; ++k) {
      for (int y = 20; y < 28; ++y) {
        for (int x = 16 * k + 4; x < 16 * k + 12; ++x) {
          for (int c = 0; c < 3; ++c) {
            ASSERT_NEAR(image.at(x, y, c), values[k][c], tolerance)
                << "levels " << black << "/" << white << ", block " << k << ", pixel (" << x << ", " << y
                << "), channel " << c;
          }
        }
      }
    }
    // The white level is full scale: the session's default saturation (integer files: 1.0) flags it.
    RadiometrySpec radiometry;
    EXPECT_EQ(SaturationLevel(radiometry, image), 1.0);
    EXPECT_GE(image.at(16 * 3 + 8, 24, 1), SaturationLevel(radiometry, image));
    EXPECT_LT(image.at(16 * 1 + 8, 24, 1), SaturationLevel(radiometry, image));
  }
}

// Float photos have no full scale: no saturation unless stated; integer photos clip at 1.0.
TEST(CameraFiles, FloatPhotosHaveNoSaturationUnlessStated) {
  ScratchDir dir;
  Image image(4, 4, 3);
  for (float& v : image.pixels) v = 3.5f;  // an HDR highlight, over 1
  WriteImage(dir / "hdr.exr", image, PixelFormat::kFloat);
  WriteImage(dir / "ldr.png", image, PixelFormat::kUint16);
  const Image hdr = ReadImage(dir / "hdr.exr"), ldr = ReadImage(dir / "ldr.png");
  EXPECT_TRUE(hdr.floating_point);
  EXPECT_FALSE(ldr.floating_point);
  RadiometrySpec radiometry;
  EXPECT_EQ(SaturationLevel(radiometry, hdr), std::numeric_limits<double>::infinity());
  EXPECT_EQ(SaturationLevel(radiometry, ldr), 1.0);
  radiometry.saturation_stated = true;
  radiometry.saturation_level = 2.0;
  EXPECT_EQ(SaturationLevel(radiometry, hdr), 2.0);
  EXPECT_EQ(SaturationLevel(radiometry, ldr), 2.0);
}

// A truncated DNG is an Error naming the file, not a crash.
TEST(CameraFiles, BrokenRawIsAnError) {
  ScratchDir dir;
  const std::string path = dir / "broken.dng";
  ASSERT_TRUE(testing::WriteTestDng(path, 32, 32, std::vector<uint16_t>(32 * 32, 500), 0, 4095));
  std::filesystem::resize_file(path, 200);
  try {
    ReadImage(path);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken.dng"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
