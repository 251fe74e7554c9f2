// The radiometric chain on hand-made images: response, black level, exposure, flat field, flags, the
// noise model's sigma, exposure groups and the HDR merge of a bracket.
#include "radiometry/radiance_image.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_io.h"
#include "core/radiometry.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

constexpr int kWidth = 8, kHeight = 6;

// A session in `dir` with a pinhole camera of kWidth x kHeight and no photos yet.
Session SmallSession(const ScratchDir& dir) {
  Session session;
  session.directory = dir.str();
  session.manifest_path = dir / "session.json";
  session.camera = Camera::Create(CameraModelId::kPinhole, kWidth, kHeight, {10.0, 10.0, 4.0, 3.0});
  return session;
}

// Writes a uniform grey image with the given file value and returns its photo spec.
PhotoSpec UniformPhoto(const ScratchDir& dir, const std::string& name, float value, double exposure_s,
                       PixelFormat format = PixelFormat::kFloat) {
  Image image(kWidth, kHeight, 3);
  for (float& v : image.pixels) v = value;
  WriteImage(dir / name, image, format);
  PhotoSpec photo;
  photo.file = name;
  photo.exposure_s = exposure_s;
  return photo;
}

TEST(RadianceImage, SrgbBlackLevelExposureAndGain) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  session.radiometry.response.kind = Response::Kind::kSrgb;
  session.radiometry.black_level = 0.02;
  PhotoSpec photo = UniformPhoto(dir, "a.exr", 0.5f, 0.25);
  photo.gain = 2.0;
  const RadianceImage image = RadianceReader(session).Read({photo}, 0.002);
  const double expected = (SrgbToLinear(0.5) - 0.02) / (0.25 * 2.0);
  for (size_t p = 0; p < image.flags.size(); ++p) {
    EXPECT_EQ(image.flags[p], 0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.radiance[3 * p + c], expected, 1e-5 * expected);
  }
  EXPECT_TRUE(image.exposures_used.empty());
}

// The floor is per channel and tested on the expected signal (the ring of 16
// neighbours at distance 2), not on the pixel's own value, so a reading that happens to be high under
// the floor is not selected and a reading that happens to be low above it is kept; a clipped channel
// leaves the others measured.
TEST(RadianceImage, PerChannelFloorOnTheExpectedSignal) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  session.radiometry.saturation_stated = true;
  session.radiometry.saturation_level = 1.0;
  Image image(kWidth, kHeight, 3);
  for (size_t p = 0; p < size_t(kWidth) * kHeight; ++p) {
    image.pixels[3 * p + 0] = 0.5f;    // red: well measured
    image.pixels[3 * p + 1] = 0.001f;  // green: under the floor everywhere ...
    image.pixels[3 * p + 2] = 0.01f;   // blue: above it everywhere ...
  }
  const size_t noisy = size_t(3) * kWidth + 4;    // pixel (4, 3)
  image.pixels[3 * noisy + 1] = 0.005f;           // ... but this green reading is high
  image.pixels[3 * noisy + 2] = 0.0f;             // ... and this blue reading is low
  const size_t clipped = size_t(1) * kWidth + 1;  // pixel (1, 1): red clipped
  image.pixels[3 * clipped + 0] = 1.0f;
  WriteImage(dir / "a.exr", image, PixelFormat::kFloat);
  PhotoSpec photo;
  photo.file = "a.exr";
  photo.exposure_s = 1.0;
  const RadianceImage out = RadianceReader(session).Read({photo}, 0.002);
  for (size_t p = 0; p < out.flags.size(); ++p) {
    EXPECT_EQ(out.channel_flags[3 * p + 0], p == clipped ? kPixelSaturated : 0) << "pixel " << p;
    EXPECT_EQ(out.channel_flags[3 * p + 1], kPixelBelowSignal) << "pixel " << p;
    EXPECT_EQ(out.channel_flags[3 * p + 2], 0) << "pixel " << p;
  }
  EXPECT_FLOAT_EQ(out.radiance[3 * noisy + 2], 0.0f);  // kept as measured: 0 is a valid reading
  // The pixel-level flags keep the old test on the pixel's own values (white-reference calibration).
  EXPECT_NE(out.flags[noisy], 0);
  EXPECT_NE(out.flags[clipped], 0);
}

TEST(RadianceImage, LookupTableMatchesTheResponse) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  for (const Response::Kind kind : {Response::Kind::kSrgb, Response::Kind::kGamma}) {
    session.radiometry.response.kind = kind;
    const RadianceReader reader(session);
    double worst = 0.0;
    for (int i = 1; i <= 4000; ++i) {
      const double encoded = i / 4000.0;
      const double exact = session.radiometry.response.ToLinear(encoded);
      worst = std::max(worst, std::abs(reader.Linear(encoded) - exact) / exact);
    }
    EXPECT_LT(worst, 3e-5) << session.radiometry.response.Describe();
  }
}

TEST(RadianceImage, FlagsSaturatedBelowSignalAndNonFinite) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  // Float files clip only where the session says so (radiometry/linear_image.h SaturationLevel).
  session.radiometry.saturation_stated = true;
  session.radiometry.saturation_level = 1.0;
  Image image(kWidth, kHeight, 3);
  for (float& v : image.pixels) v = 0.4f;
  image.at(1, 1, 2) = 1.0f;           // one channel clipped
  image.at(2, 1, 0) = 0.001f;         // darkest channel below the floor
  image.at(3, 1, 1) = std::nanf("");  // not finite
  WriteImage(dir / "a.exr", image, PixelFormat::kFloat);
  PhotoSpec photo;
  photo.file = "a.exr";
  const RadianceImage out = RadianceReader(session).Read({photo}, 0.002);
  EXPECT_EQ(out.flags[out.Index(1, 1)], kPixelSaturated);
  EXPECT_EQ(out.flags[out.Index(2, 1)], kPixelBelowSignal);
  EXPECT_TRUE(out.flags[out.Index(3, 1)] & kPixelNonFinite);
  EXPECT_EQ(out.flags[out.Index(0, 0)], 0);
}

// The single-exposure sigma is the noise model's: shot + read + quantization through the response.
TEST(RadianceImage, SigmaFromTheNoiseModel) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  session.radiometry.noise = CameraNoise{20000.0, 4.0, 0};
  const PhotoSpec photo = UniformPhoto(dir, "a.exr", 0.25f, 0.5);
  const RadianceImage image = RadianceReader(session).Read({photo}, 0.002);
  const double expected = std::sqrt(0.25 / 20000.0 + (4.0 / 20000.0) * (4.0 / 20000.0)) / 0.5;
  EXPECT_NEAR(image.sigma[0], expected, 1e-4 * expected);
}

TEST(RadianceImage, FlatFieldDividesAndIsChecked) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  Image flat(kWidth, kHeight, 1);
  for (float& v : flat.pixels) v = 0.5f;
  flat.at(kWidth / 2, kHeight / 2, 0) = 1.0f;
  WriteImage(dir / "flat.exr", flat, PixelFormat::kFloat);
  session.radiometry.flat_field = "flat.exr";
  const PhotoSpec photo = UniformPhoto(dir, "a.exr", 0.3f, 1.0);
  const RadianceImage image = RadianceReader(session).Read({photo}, 0.002);
  EXPECT_NEAR(image.radiance[3 * image.Index(0, 0)], 0.6, 1e-6);
  EXPECT_NEAR(image.radiance[3 * image.Index(kWidth / 2, kHeight / 2) + 2], 0.3, 1e-6);

  // Wrong size: an error naming the file and the manifest's field.
  WriteImage(dir / "small.exr", Image(kWidth - 1, kHeight, 1), PixelFormat::kFloat);
  session.radiometry.flat_field = "small.exr";
  try {
    RadianceReader reader(session);
    FAIL() << "a mis-sized flat field was accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("small.exr"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("/radiometry/flat_field"), std::string::npos) << error.what();
  }
  // A zero: not a sensitivity.
  flat.at(0, 0, 0) = 0.0f;
  WriteImage(dir / "zero.exr", flat, PixelFormat::kFloat);
  session.radiometry.flat_field = "zero.exr";
  EXPECT_THROW(RadianceReader reader(session), Error);
}

TEST(RadianceImage, ExposureGroupsByBracketAndByPose) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  const Rigid3d a(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  const Rigid3d b(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0.1, 1));
  auto photo = [](const Rigid3d& pose, std::optional<int> bracket, PhotoRole role = PhotoRole::kMeasurement) {
    PhotoSpec p;
    p.file = "x.png";
    p.camera_from_world = pose;
    p.bracket = bracket;
    p.role = role;
    return p;
  };
  session.photos = {photo(a, std::nullopt),
                    photo(b, 7),
                    photo(a, std::nullopt),
                    photo(b, 7),
                    photo(b, std::nullopt, PhotoRole::kTargets),
                    photo(b, 8)};
  // A bracket: the exposures of one pose differ.
  session.photos[2].exposure_s = 4.0;
  session.photos[3].gain = 0.25;
  const std::vector<std::vector<size_t>> groups = ExposureGroups(session);
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0], (std::vector<size_t>{0, 2}));
  EXPECT_EQ(groups[1], (std::vector<size_t>{1, 3}));
  EXPECT_EQ(groups[2], (std::vector<size_t>{5}));
  // A bracket whose poses differ is refused, naming the photo.
  session.photos[3].camera_from_world = a;
  try {
    ExposureGroups(session);
    FAIL() << "a bracket of two poses was accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("/photos/3/bracket"), std::string::npos) << error.what();
  }
}

// No silent merge (the real-rigs issue): two photos of one pose and one exposure (as under two
// lights of a dome, or the same photo twice) are an error naming both files, with or without a bracket
// id; different exposures of one pose still merge.
TEST(RadianceImage, SamePoseAndExposureIsAnErrorNamingBothPhotos) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  const Rigid3d pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  PhotoSpec first, second;
  first.file = "light-07.png";
  second.file = "light-12.png";
  first.camera_from_world = second.camera_from_world = pose;
  for (const std::optional<int> bracket : {std::optional<int>(), std::optional<int>(3)}) {
    first.bracket = second.bracket = bracket;
    session.photos = {first, second};
    try {
      ExposureGroups(session);
      FAIL() << "two photos of one pose and exposure were merged";
    } catch (const Error& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("light-07.png"), std::string::npos) << message;
      EXPECT_NE(message.find("light-12.png"), std::string::npos) << message;
      EXPECT_NE(message.find("/photos/1"), std::string::npos) << message;
    }
    // A real bracket (exposure x 4) still merges.
    session.photos[1].exposure_s = 4.0 * session.photos[0].exposure_s;
    const std::vector<std::vector<size_t>> groups = ExposureGroups(session);
    ASSERT_EQ(groups.size(), 1u);
    EXPECT_EQ(groups[0], (std::vector<size_t>{0, 1}));
  }
}

// The silent-merge case of the real-rigs issue, with lights named: two photos of one pose under two
// lights are two measurements (two groups), whatever their exposures; the same pose, light and
// exposure twice is an error naming both files; a real bracket (one pose, one light, two exposures)
// still merges; an explicit bracket id across two lights is an error naming the lights.
TEST(RadianceImage, PhotosOfOnePoseUnderTwoLightsAreTwoMeasurements) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  Light l07, l12;
  l07.id = "L07";
  l12.id = "L12";
  l12.position = Eigen::Vector3d(1.0, 0.0, 0.0);
  session.lights = {l07, l12};
  const Rigid3d pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  PhotoSpec first, second;
  first.file = "dome-07.png";
  second.file = "dome-12.png";
  first.camera_from_world = second.camera_from_world = pose;
  first.light = 0;
  second.light = 1;
  session.photos = {first, second};
  std::vector<std::vector<size_t>> groups = ExposureGroups(session);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0], (std::vector<size_t>{0}));
  EXPECT_EQ(groups[1], (std::vector<size_t>{1}));
  // Same pose, same light, same exposure: an error naming both files and the light.
  session.photos[1].light = 0;
  try {
    ExposureGroups(session);
    FAIL() << "two photos of one pose, light and exposure were accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("dome-07.png"), std::string::npos) << message;
    EXPECT_NE(message.find("dome-12.png"), std::string::npos) << message;
    EXPECT_NE(message.find("L07"), std::string::npos) << message;
  }
  // A real bracket of one pose and one light still merges.
  session.photos[1].exposure_s = 4.0;
  groups = ExposureGroups(session);
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0], (std::vector<size_t>{0, 1}));
  // A third photo of the pose under the other light, exposed like the first: its own measurement.
  PhotoSpec third = first;
  third.file = "dome-12b.png";
  third.light = 1;
  session.photos.push_back(third);
  groups = ExposureGroups(session);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[1], (std::vector<size_t>{2}));
  // An explicit bracket id must agree in light.
  for (PhotoSpec& photo : session.photos) photo.bracket = 5;
  try {
    ExposureGroups(session);
    FAIL() << "a bracket across two lights was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/photos/2/bracket"), std::string::npos) << message;
    EXPECT_NE(message.find("light L12"), std::string::npos) << message;
    EXPECT_NE(message.find("light L07"), std::string::npos) << message;
  }
}

// More than 255 exposures of one pose is an error naming the photo, not an internal check.
TEST(RadianceImage, TooManyExposuresOfOnePoseIsAnError) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  PhotoSpec photo;
  photo.file = "x.png";
  photo.camera_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  session.photos.clear();
  for (int i = 0; i < 260; ++i) {
    photo.exposure_s = 0.001 * (i + 1);
    session.photos.push_back(photo);
  }
  try {
    ExposureGroups(session);
    FAIL() << "260 exposures of one pose were accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("/photos/255"), std::string::npos) << error.what();
  }
}

// A bracket: the long exposure clips where the short one does not; the merge uses what is usable,
// inverse-variance weighted, and flags only where every exposure fails.
TEST(RadianceImage, BracketMergesWhereUsable) {
  ScratchDir dir;
  Session session = SmallSession(dir);
  session.radiometry.saturation_stated = true;  // float files: the clip level is the session's
  session.radiometry.saturation_level = 1.0;
  session.radiometry.noise = CameraNoise{20000.0, 4.0, 0};
  // True radiance 0.5 everywhere, except 4.0 at (1, 1) and 1e-4 at (2, 2).
  auto exposure = [&](const std::string& name, double exposure_s) {
    Image image(kWidth, kHeight, 3);
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const double radiance = x == 1 && y == 1 ? 4.0 : x == 2 && y == 2 ? 1e-4 : 0.5;
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(std::min(1.0, radiance * exposure_s));
      }
    }
    WriteImage(dir / name, image, PixelFormat::kFloat);
    PhotoSpec photo;
    photo.file = name;
    photo.exposure_s = exposure_s;
    return photo;
  };
  const std::vector<PhotoSpec> bracket = {exposure("long.exr", 1.6), exposure("short.exr", 0.2)};
  const RadianceImage merged = RadianceReader(session).Read(bracket, 0.002);
  ASSERT_EQ(merged.exposures_used.size(), merged.flags.size());
  // Both usable: the mean, with a sigma below either exposure's.
  const size_t both = merged.Index(0, 0);
  EXPECT_EQ(merged.flags[both], 0);
  EXPECT_EQ(merged.exposures_used[both], 2);
  EXPECT_NEAR(merged.radiance[3 * both], 0.5, 1e-6);
  const RadianceImage long_only = RadianceReader(session).Read({bracket[0]}, 0.002);
  EXPECT_LT(merged.sigma[3 * both], long_only.sigma[3 * both]);
  EXPECT_GT(merged.sigma[3 * both], 0.9 * long_only.sigma[3 * both]);  // the long exposure dominates
  // Clipped in the long exposure: the short one alone.
  const size_t bright = merged.Index(1, 1);
  EXPECT_EQ(long_only.flags[bright], kPixelSaturated);
  EXPECT_EQ(merged.flags[bright], 0);
  EXPECT_EQ(merged.exposures_used[bright], 1);
  EXPECT_NEAR(merged.radiance[3 * bright], 4.0, 1e-5);
  // Below the floor in its own readings but not in its neighbours' (the expected signal):
  // the pixel-level flag (own values) says below_signal, but every channel is measured, from both
  // exposures, at its true value: the floor selects on the expected signal, not on the reading.
  const size_t dark = merged.Index(2, 2);
  EXPECT_EQ(merged.flags[dark], kPixelBelowSignal);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(merged.channel_flags[3 * dark + c], 0) << "channel " << c;
  EXPECT_EQ(merged.exposures_used[dark], 2);
  EXPECT_NEAR(merged.radiance[3 * dark], 1e-4, 1e-7);
}

// A 3-exposure sRGB bracket of W x H noisy pixels (some clipped, some dark, one NaN) for the window tests.
std::vector<PhotoSpec> NoisyBracket(const ScratchDir& dir, int width, int height) {
  std::vector<PhotoSpec> bracket;
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) * (1.0 / 9007199254740992.0);
  };
  const double exposures[3] = {1.0, 0.25, 0.0625};
  for (int e = 0; e < 3; ++e) {
    Image image(width, height, 3);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        // A radiance field from 1e-4 (under the floor) to 3 (clipped in the long exposures).
        const double base = 3.0 * std::pow(double(x + 1) / width, 4.0) * (0.5 + double(y) / height);
        for (int c = 0; c < 3; ++c) {
          const double linear = std::min(1.0, base * (0.8 + 0.4 * uniform()) * exposures[e] * (1.0 + 0.3 * c));
          image.at(x, y, c) = static_cast<float>(LinearToSrgb(linear));
        }
      }
    }
    if (e == 0) image.at(3, 4, 1) = std::numeric_limits<float>::quiet_NaN();
    const std::string name = "bracket" + std::to_string(e) + ".exr";
    WriteImage(dir / name, image, PixelFormat::kFloat);
    PhotoSpec photo;
    photo.file = name;
    photo.exposure_s = exposures[e];
    bracket.push_back(photo);
  }
  return bracket;
}

// The derenderer merges only the pixels it needs (RadianceReader::PrepareWindow and
// RadianceWindow::At); each must read exactly what ReadWindow stores for it, for single photos and
// brackets, in windows at the photo's edges, inside it, and too small for a ring.
TEST(RadianceImage, WindowMergedOnDemandIsReadWindowBitForBit) {
  ScratchDir dir;
  constexpr int kW = 61, kH = 83;  // several of the floor pass's row blocks
  Session session = SmallSession(dir);
  session.camera = Camera::Create(CameraModelId::kPinhole, kW, kH, {50.0, 50.0, 30.0, 40.0});
  session.radiometry.response.kind = Response::Kind::kSrgb;
  session.radiometry.black_level = 0.001;
  session.radiometry.saturation_stated = true;
  session.radiometry.saturation_level = 0.98;
  session.radiometry.noise = CameraNoise{20000.0, 4.0, 12};
  const std::vector<PhotoSpec> bracket = NoisyBracket(dir, kW, kH);
  const RadianceReader reader(session);
  const std::vector<PixelWindow> windows = {{0, 0, kW, kH},   {7, 5, 50, 77},   {0, 60, 9, kH},
                                            {20, 20, 22, 22}, {30, 31, 31, 32}, {10, 10, 13, 40}};
  for (const std::vector<PhotoSpec>& exposures :
       {bracket, std::vector<PhotoSpec>{bracket[0]}, std::vector<PhotoSpec>{bracket[2], bracket[1]}}) {
    RadianceWindow lazy;  // reused across windows, as the derenderer reuses it across photos
    for (const PixelWindow& w : windows) {
      SCOPED_TRACE(std::to_string(exposures.size()) + " exposures, window " + std::to_string(w.x0) + "," +
                   std::to_string(w.y0) + " to " + std::to_string(w.x1) + "," + std::to_string(w.y1));
      std::vector<Image> decoded;
      RadianceImage image;
      reader.ReadWindow(exposures, 0.002, w, &decoded, &image);
      reader.PrepareWindow(exposures, 0.002, w, &lazy);
      int mismatches = 0, flagged = 0;
      for (int y = w.y0; y < w.y1; ++y) {
        for (int x = w.x0; x < w.x1; ++x) {
          PixelRadiance pixel;
          lazy.At(x, y, &pixel);
          const size_t p = image.Index(x, y);
          for (int c = 0; c < 3; ++c) {
            mismatches += std::memcmp(&pixel.radiance[c], &image.radiance[3 * p + c], sizeof(float)) != 0;
            mismatches += std::memcmp(&pixel.sigma[c], &image.sigma[3 * p + c], sizeof(float)) != 0;
            mismatches += pixel.channel_flags[c] != image.channel_flags[3 * p + c];
            flagged += pixel.channel_flags[c] != 0;
          }
          mismatches += pixel.exposures != (image.exposures_used.empty() ? 1 : image.exposures_used[p]);
        }
      }
      EXPECT_EQ(mismatches, 0);
      if (w.x1 - w.x0 == kW) {
        EXPECT_GT(flagged, 0);  // the test reaches the flags
      }
    }
  }
}

// The floor's expected signal against its definition, computed the slow way: the mean linear signal
// of the ring of 16 pixels around each pixel (those inside the window), in a window larger than the
// pass's row blocks, so block edges and window edges are both crossed.
TEST(RadianceImage, FloorRingMatchesItsDefinitionAcrossRowBlocks) {
  ScratchDir dir;
  constexpr int kW = 37, kH = 101;
  Session session = SmallSession(dir);
  session.camera = Camera::Create(CameraModelId::kPinhole, kW, kH, {50.0, 50.0, 18.0, 50.0});
  session.radiometry.response.kind = Response::Kind::kSrgb;
  session.radiometry.saturation_stated = true;
  session.radiometry.saturation_level = 2.0;  // nothing clips: the floor alone decides
  const PhotoSpec photo = NoisyBracket(dir, kW, kH)[1];
  const Image file = ReadImage(dir / photo.file);
  const RadianceReader reader(session);
  const PixelWindow w{2, 3, kW - 1, kH - 2};
  const double min_signal = 0.01;
  RadianceWindow lazy;
  reader.PrepareWindow({photo}, min_signal, w, &lazy);
  int compared = 0, below = 0;
  for (int y = w.y0; y < w.y1; ++y) {
    for (int x = w.x0; x < w.x1; ++x) {
      PixelRadiance pixel;
      lazy.At(x, y, &pixel);
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        int count = 0;
        for (int dy = -2; dy <= 2; ++dy) {
          for (int dx = -2; dx <= 2; ++dx) {
            const int u = x + dx, v = y + dy;
            if (std::max(std::abs(dx), std::abs(dy)) != 2 || u < w.x0 || u >= w.x1 || v < w.y0 || v >= w.y1) continue;
            const double value = file.at(u, v, c);
            sum += std::isfinite(value) ? reader.Linear(value) : 0.0;
            ++count;
          }
        }
        const double mean = sum / count;
        if (std::abs(mean - min_signal) < 1e-4 * min_signal) continue;  // rounding could go either way
        ++compared;
        const bool expected_below = mean < min_signal;
        below += expected_below;
        EXPECT_EQ((pixel.channel_flags[c] & kPixelBelowSignal) != 0, expected_below)
            << "pixel " << x << "," << y << " channel " << c << ": ring mean " << mean;
      }
    }
  }
  EXPECT_GT(compared, 3 * (w.x1 - w.x0) * (w.y1 - w.y0) * 9 / 10);
  EXPECT_GT(below, 100);
  EXPECT_LT(below, compared - 100);
}

}  // namespace
}  // namespace ibrdf
