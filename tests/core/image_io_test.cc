// Tests of core/image_io.h: images written and read back through OpenImageIO keep their values within
// the quantization of the stored format, and bad files are Errors naming the path.
#include "core/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// A fresh, empty folder per test, removed afterwards.
class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = scratch_.str(); }
  testing::ScratchDir scratch_;

  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  // The names of the files in the folder.
  std::vector<std::string> Listing() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    return names;
  }

  std::string dir_;
};

// Random values in [0, 1], with the exact ends included.
Image RandomImage(int width, int height, int channels, unsigned seed) {
  Image image(width, height, channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  for (float& v : image.pixels) v = value(rng);
  image.pixels[0] = 0.0f;
  image.pixels[1] = 1.0f;
  return image;
}

// Writes, reads back, and checks size and values within `tolerance`.
void ExpectRoundTrip(const std::string& path, const Image& image, PixelFormat format, double tolerance) {
  WriteImage(path, image, format);
  const Image read = ReadImage(path);
  ASSERT_EQ(read.width, image.width) << path;
  ASSERT_EQ(read.height, image.height) << path;
  ASSERT_EQ(read.channels, image.channels) << path;
  ASSERT_EQ(read.pixels.size(), image.pixels.size()) << path;
  double max_error = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    max_error = std::max(max_error, std::abs(double(read.pixels[i]) - double(image.pixels[i])));
  }
  EXPECT_LE(max_error, tolerance) << path;
  // Pixel (x, y) is where at() says it is: the layout is row-major and not transposed.
  EXPECT_NEAR(read.at(image.width - 1, 0, 0), image.at(image.width - 1, 0, 0), tolerance) << path;
  EXPECT_NEAR(read.at(0, image.height - 1, image.channels - 1), image.at(0, image.height - 1, image.channels - 1),
              tolerance)
      << path;
}

// 8-bit PNG: values survive to half a quantization step, 0.5/255.
TEST_F(ImageIoTest, Png8BitRoundTrip) {
  ExpectRoundTrip(Path("rgb8.png"), RandomImage(17, 11, 3, 1), PixelFormat::kUint8, 0.5 / 255 + 1e-6);
  ExpectRoundTrip(Path("grey8.png"), RandomImage(5, 9, 1, 2), PixelFormat::kUint8, 0.5 / 255 + 1e-6);
}

// 8-bit values on the quantization grid come back exactly (k / 255).
TEST_F(ImageIoTest, Png8BitGridValuesAreExact) {
  Image image(256, 1, 1);
  for (int k = 0; k < 256; ++k) image.at(k, 0, 0) = k / 255.0f;
  ExpectRoundTrip(Path("ramp.png"), image, PixelFormat::kUint8, 1e-7);
}

// 16-bit PNG and TIFF: half a step of 1/65535.
TEST_F(ImageIoTest, Png16BitRoundTrip) {
  ExpectRoundTrip(Path("rgb16.png"), RandomImage(13, 7, 3, 3), PixelFormat::kUint16, 0.5 / 65535 + 1e-7);
}

TEST_F(ImageIoTest, Tiff16BitRoundTrip) {
  ExpectRoundTrip(Path("rgb16.tif"), RandomImage(13, 7, 3, 4), PixelFormat::kUint16, 0.5 / 65535 + 1e-7);
  ExpectRoundTrip(Path("rgba16.tiff"), RandomImage(6, 4, 4, 5), PixelFormat::kUint16, 0.5 / 65535 + 1e-7);
}

// Float EXR is lossless, including values outside [0, 1] (HDR radiance).
TEST_F(ImageIoTest, FloatExrIsExact) {
  Image image = RandomImage(19, 5, 3, 6);
  image.pixels[2] = 1234.5f;
  image.pixels[3] = -0.25f;
  image.pixels[4] = 1e-20f;
  ExpectRoundTrip(Path("radiance.exr"), image, PixelFormat::kFloat, 0.0);
}

// Half EXR keeps 11 significant bits.
TEST_F(ImageIoTest, HalfExrKeepsHalfPrecision) {
  ExpectRoundTrip(Path("half.exr"), RandomImage(8, 8, 3, 7), PixelFormat::kHalf, 1.0 / 2048);
}

// Integer formats clamp values outside [0, 1].
TEST_F(ImageIoTest, IntegerFormatsClamp) {
  Image image(2, 1, 1);
  image.at(0, 0, 0) = -0.5f;
  image.at(1, 0, 0) = 1.5f;
  for (PixelFormat format : {PixelFormat::kUint8, PixelFormat::kUint16}) {
    const std::string path = Path(format == PixelFormat::kUint8 ? "clamp8.png" : "clamp16.png");
    WriteImage(path, image, format);
    const Image read = ReadImage(path);
    EXPECT_EQ(read.at(0, 0, 0), 0.0f) << path;
    EXPECT_EQ(read.at(1, 0, 0), 1.0f) << path;
  }
}

// The header alone gives size and channels.
TEST_F(ImageIoTest, ReadImageSpec) {
  WriteImage(Path("spec.png"), RandomImage(23, 4, 3, 8), PixelFormat::kUint8);
  const ImageSpec spec = ReadImageSpec(Path("spec.png"));
  EXPECT_EQ(spec.width, 23);
  EXPECT_EQ(spec.height, 4);
  EXPECT_EQ(spec.channels, 3);
  WriteImage(Path("spec.exr"), RandomImage(3, 31, 1, 9), PixelFormat::kFloat);
  const ImageSpec exr = ReadImageSpec(Path("spec.exr"));
  EXPECT_EQ(exr.width, 3);
  EXPECT_EQ(exr.height, 31);
  EXPECT_EQ(exr.channels, 1);
}

// Expects `call` to throw an Error whose message names `path`.
template <typename Call>
void ExpectErrorNamingPath(Call call, const std::string& path) {
  try {
    call();
    ADD_FAILURE() << "expected an Error for " << path;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST_F(ImageIoTest, MissingFileIsAnErrorNamingIt) {
  const std::string path = Path("no_such_photo.png");
  ExpectErrorNamingPath([&] { ReadImage(path); }, path);
  ExpectErrorNamingPath([&] { ReadImageSpec(path); }, path);
}

// Random bytes with a .png extension: an Error naming the file, not a crash or garbage pixels.
TEST_F(ImageIoTest, CorruptFileIsAnErrorNamingIt) {
  const std::string path = Path("corrupt.png");
  {
    std::ofstream out(path, std::ios::binary);
    std::mt19937 rng(10);
    for (int i = 0; i < 4096; ++i) out.put(static_cast<char>(rng() & 0xff));
  }
  ExpectErrorNamingPath([&] { ReadImage(path); }, path);
  ExpectErrorNamingPath([&] { ReadImageSpec(path); }, path);
}

// A real PNG cut short: the header reads, the pixels do not; still an Error naming the file.
TEST_F(ImageIoTest, TruncatedFileIsAnErrorNamingIt) {
  const std::string path = Path("truncated.png");
  WriteImage(path, RandomImage(64, 64, 3, 11), PixelFormat::kUint8);
  fs::resize_file(path, fs::file_size(path) / 2);
  ExpectErrorNamingPath([&] { ReadImage(path); }, path);
}

// A folder is not an image.
TEST_F(ImageIoTest, DirectoryIsAnError) {
  fs::create_directories(Path("folder.png"));
  ExpectErrorNamingPath([&] { ReadImage(Path("folder.png")); }, Path("folder.png"));
}

// WriteImage is atomic: after a write only the final file is in the folder, and a rewrite replaces it.
TEST_F(ImageIoTest, WriteLeavesNoTemporaryFile) {
  WriteImage(Path("photo.png"), RandomImage(8, 8, 3, 12), PixelFormat::kUint8);
  WriteImage(Path("photo.exr"), RandomImage(8, 8, 3, 13), PixelFormat::kFloat);
  WriteImage(Path("photo.png"), RandomImage(4, 4, 3, 14), PixelFormat::kUint16);
  std::vector<std::string> names = Listing();
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"photo.exr", "photo.png"}));
  EXPECT_EQ(ReadImageSpec(Path("photo.png")).width, 4);
}

// A failed write (no writer for the extension, or no such folder) is an Error naming the path and
// leaves nothing behind.
TEST_F(ImageIoTest, FailedWriteIsAnErrorAndLeavesNothing) {
  const Image image = RandomImage(4, 4, 3, 15);
  const std::string unknown = Path("photo.notanimageformat");
  ExpectErrorNamingPath([&] { WriteImage(unknown, image, PixelFormat::kUint8); }, unknown);
  const std::string nowhere = Path("missing_folder/photo.png");
  ExpectErrorNamingPath([&] { WriteImage(nowhere, image, PixelFormat::kUint8); }, nowhere);
  EXPECT_TRUE(Listing().empty());
}

// The libpng fast path gives OpenImageIO's floats bit for bit: every 16-bit and every 8-bit value, grey
// and RGB; PNGs it does not handle (an alpha channel) still read, through OpenImageIO.
TEST_F(ImageIoTest, PlainPngFastPathMatchesOpenImageIO) {
  for (const auto& [format, levels] : {std::pair<PixelFormat, int>(PixelFormat::kUint16, 65536),
                                       std::pair<PixelFormat, int>(PixelFormat::kUint8, 256)}) {
    for (int channels : {1, 3, 4}) {
      Image image(256, (levels * 3 + 255) / 256, channels);
      for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = float(i % levels) / float(levels - 1);
      const std::string path = Path("levels-" + std::to_string(levels) + "-" + std::to_string(channels) + ".png");
      WriteImage(path, image, format);
      Image fast, reference;
      ReadImage(path, &fast);
      ReadImageThroughOpenImageIO(path, &reference);
      ASSERT_EQ(fast.channels, channels) << path;
      ASSERT_EQ(fast.width, reference.width) << path;
      ASSERT_EQ(fast.height, reference.height) << path;
      ASSERT_EQ(fast.pixels.size(), reference.pixels.size()) << path;
      size_t different = 0;
      for (size_t i = 0; i < fast.pixels.size(); ++i) different += fast.pixels[i] != reference.pixels[i];
      EXPECT_EQ(different, 0u) << path;
      const ImageSpec spec = ReadImageSpec(path);
      EXPECT_EQ(spec.width, reference.width);
      EXPECT_EQ(spec.channels, channels);
    }
  }
  // A corrupt PNG is an error naming the file, not a crash.
  const std::string corrupt = Path("corrupt.png");
  {
    std::ifstream in(Path("levels-256-3.png"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bytes.resize(bytes.size() / 2);
    std::ofstream(corrupt, std::ios::binary) << bytes;
  }
  Image image;
  ExpectErrorNamingPath([&] { ReadImage(corrupt, &image); }, corrupt);
}

// ReadImageRegion gives ReadImage's values inside the region (clipped to the image) for PNGs
// (8 and 16 bits, grey and RGB: the libpng path stops after the region's last row) and for a format
// decoded whole (EXR); a region reaching past the image or empty reads without error; a PNG cut off
// inside the region is an error naming the file, one cut off after it is not (its rows are never
// decoded).
TEST_F(ImageIoTest, RegionReadMatchesTheWholeImageInside) {
  struct Case {
    std::string name;
    PixelFormat format;
    int channels;
  };
  const std::vector<Case> cases = {{"r16.png", PixelFormat::kUint16, 3},
                                   {"g16.png", PixelFormat::kUint16, 1},
                                   {"r8.png", PixelFormat::kUint8, 3},
                                   {"r.exr", PixelFormat::kFloat, 3}};
  const std::vector<ImageRegion> regions = {{0, 0, 57, 43}, {5, 7, 30, 20},   {0, 30, 57, 43}, {40, 0, 80, 10},
                                            {-3, -2, 4, 3}, {10, 10, 10, 20}, {56, 42, 57, 43}};
  for (const Case& c : cases) {
    const std::string path = Path(c.name);
    WriteImage(path, RandomImage(57, 43, c.channels, 7), c.format);
    const Image whole = ReadImage(path);
    Image part;  // reused across regions, as the derenderer reuses its buffers
    for (const ImageRegion& r : regions) {
      SCOPED_TRACE(c.name + " region " + std::to_string(r.x0) + "," + std::to_string(r.y0) + " to " +
                   std::to_string(r.x1) + "," + std::to_string(r.y1));
      // Fill the reused buffer with a value no file holds, so a pixel the read skipped would show.
      std::fill(part.pixels.begin(), part.pixels.end(), -1.0f);
      ReadImageRegion(path, r, &part);
      ASSERT_EQ(part.width, whole.width);
      ASSERT_EQ(part.height, whole.height);
      ASSERT_EQ(part.channels, whole.channels);
      ASSERT_EQ(part.pixels.size(), whole.pixels.size());
      EXPECT_EQ(part.floating_point, whole.floating_point);
      size_t compared = 0, different = 0;
      for (int y = std::max(r.y0, 0); y < std::min(r.y1, whole.height); ++y) {
        for (int x = std::max(r.x0, 0); x < std::min(r.x1, whole.width); ++x) {
          for (int k = 0; k < whole.channels; ++k) {
            ++compared;
            different += part.at(x, y, k) != whole.at(x, y, k);
          }
        }
      }
      EXPECT_EQ(different, 0u);
      if (r.x1 > r.x0 && r.y1 > r.y0) {
        EXPECT_GT(compared, 0u);
      }
    }
  }
  // A PNG cut off at half its bytes (large enough that libpng's reads of 8 KiB stay clear of the cut
  // for the first rows): a region above the cut reads; one reaching below it is an error naming the file.
  const std::string full = Path("big.png"), cut = Path("cut.png");
  WriteImage(full, RandomImage(300, 200, 3, 11), PixelFormat::kUint16);
  {
    std::ifstream in(full, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    bytes.resize(bytes.size() / 2);
    std::ofstream(cut, std::ios::binary) << bytes;
  }
  const Image whole = ReadImage(full);
  Image part;
  ReadImageRegion(cut, ImageRegion{10, 0, 300, 5}, &part);
  for (int x = 10; x < 300; ++x) EXPECT_EQ(part.at(x, 4, 2), whole.at(x, 4, 2));
  ExpectErrorNamingPath([&] { ReadImageRegion(cut, ImageRegion{0, 150, 300, 200}, &part); }, cut);
}

TEST(IsRawExtension, KnowsCameraRawFormats) {
  EXPECT_TRUE(IsRawExtension("a/IMG_0001.CR2"));
  EXPECT_TRUE(IsRawExtension("b.nef"));
  EXPECT_TRUE(IsRawExtension("c.dng"));
  EXPECT_TRUE(IsRawExtension("d.ARW"));
  EXPECT_FALSE(IsRawExtension("e.png"));
  EXPECT_FALSE(IsRawExtension("f.tif"));
  EXPECT_FALSE(IsRawExtension("g.exr"));
  EXPECT_FALSE(IsRawExtension("cr2"));
  EXPECT_FALSE(IsRawExtension(""));
}

}  // namespace
}  // namespace ibrdf
