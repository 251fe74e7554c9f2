// The synthetic session generator: reproducible, loadable, and physically placed as in the paper.
#include "derender/synthetic.h"

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
