// The synthetic session generator: reproducible, loadable, and physically placed as in the paper.
#include "derender/synthetic.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_io.h"
#include "core/session.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(Synth, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(SynthOptions().Check(&why)) << why;
  EXPECT_TRUE(CameraEffects().Check(&why)) << why;
  EXPECT_TRUE(CameraEffects::None().Check(&why)) << why;
  SynthOptions bad;
  bad.camera_distance = 0.01;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(Synth, FixedSeedIsReproducibleAndSeedsDiffer) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.num_photos = 2;
  options.width = 160;
  options.height = 120;
  MakeSession(dir / "a", options, material);
  MakeSession(dir / "b", options, material);
  options.seed = 2;
  MakeSession(dir / "c", options, material);
  for (const char* photo : {"/photos/000.png", "/photos/001.png"}) {
    EXPECT_EQ(ReadBytes(dir / "a" + photo), ReadBytes(dir / "b" + photo));
    EXPECT_NE(ReadBytes(dir / "a" + photo), ReadBytes(dir / "c" + photo));
  }
}

TEST(Synth, SessionLoadsWithPosesOnTheArc) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.num_photos = 5;
  options.width = 160;
  options.height = 120;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.photos.size(), 5u);
  const Eigen::Vector3d to_light = (session.light.position - session.sample.center).normalized();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    ASSERT_TRUE(photo.camera_from_world.has_value());
    EXPECT_GT(photo.exposure_s, 0.0);
    const Eigen::Vector3d center = photo.camera_from_world->Inverse().translation;
    EXPECT_NEAR((center - session.sample.center).norm(), options.camera_distance, 1e-9);
    const double azimuth = std::acos(to_light.dot((center - session.sample.center).normalized())) * 180.0 / M_PI;
    EXPECT_NEAR(azimuth, options.arc_start_deg + i * (options.arc_end_deg - options.arc_start_deg) / 4, 1e-6);
    // The sample centre projects to the principal point.
    const Eigen::Vector2d pixel = session.camera.ImageFromCamera(*photo.camera_from_world * session.sample.center);
    EXPECT_NEAR(pixel.x(), 80.0, 1e-6);
    EXPECT_NEAR(pixel.y(), 60.0, 1e-6);
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "s/truth.json"));
}

TEST(Synth, AutoExposurePutsThe99thPercentileAtTheTarget) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.num_photos = 1;
  options.width = 200;
  options.height = 150;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  const Image image = ReadImage(session.PhotoPath(0));
  std::vector<float> lit;
  for (size_t p = 0; p < image.pixels.size(); p += 3) {
    if (image.pixels[p] > 0.0f) lit.push_back(image.pixels[p]);
  }
  std::sort(lit.begin(), lit.end());
  ASSERT_FALSE(lit.empty());
  EXPECT_NEAR(lit[size_t(0.99 * (lit.size() - 1))], options.exposure_target, 0.02);
}

// Supersampling averages n x n rays over the pixel: inside the disc it matches the centre ray of a
// smooth (Lambertian) image closely, and pixels on the silhouette get partial coverage.
TEST(Synth, SupersamplingAveragesOverThePixel) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.num_photos = 1;
  options.width = 200;
  options.height = 150;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  std::vector<uint8_t> mask;
  const Image centre = RenderRadiance(session, 0, material, 1, &mask);
  const Image averaged = RenderRadiance(session, 0, material, 4, nullptr);
  double peak = 0.0;
  for (float v : centre.pixels) peak = std::max(peak, double(v));
  int interior = 0, partial = 0;
  std::vector<double> ratios;
  for (int y = 1; y + 1 < centre.height; ++y) {
    for (int x = 1; x + 1 < centre.width; ++x) {
      const bool all_hit = mask[y * centre.width + x] && mask[y * centre.width + x - 1] &&
                           mask[y * centre.width + x + 1] && mask[(y - 1) * centre.width + x] &&
                           mask[(y + 1) * centre.width + x];
      const double a = centre.at(x, y, 0), b = averaged.at(x, y, 0);
      if (all_hit && a > 0.2 * peak) {
        ++interior;
        ratios.push_back(b / a);
        // Second-order shading change across a (large) pixel: small, largest where the normal turns fast.
        EXPECT_NEAR(b / a, 1.0, 0.02) << x << "," << y;
      }
      if (!mask[y * centre.width + x] && b > 0.0) ++partial;  // centre misses, some sub-rays hit
    }
  }
  EXPECT_GT(interior, 1000);
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.001);
  EXPECT_GT(partial, 10);
}

TEST(Synth, ExistingOutputIsNotReplacedWithoutOverwrite) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.num_photos = 1;
  options.width = 64;
  options.height = 48;
  MakeSession(dir / "s", options, material);
  EXPECT_THROW(WriteSyntheticSession(options, material, "test", dir / "s", /*overwrite=*/false), Error);
  EXPECT_TRUE(std::filesystem::exists(dir / "s/session.json"));
}

}  // namespace
}  // namespace ibrdf
