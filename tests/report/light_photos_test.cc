// report/light_photos.h: a multi-light session's lights in the report's data, with a thumbnail of a
// photo under each; nothing for a one-light session.
#include "report/light_photos.h"

#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/sample_file.h"
#include "derender/derenderer.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

// A noise-free Lambertian session of `rig` with `photos` photos, derendered to dir/samples.npy.
std::string Derendered(const ScratchDir& dir, SynthRig rig, int photos) {
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.rig.rig = rig;
  options.rig.num_photos = photos;
  options.rig.width = 200;
  options.rig.height = 150;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  const std::string samples = dir / "samples.npy";
  DerenderToFile(session, DerenderOptions(), samples);
  return samples;
}

TEST(LightPhotos, DomeListsEveryLightWithAThumbnail) {
  ScratchDir dir;
  const std::string samples_path = Derendered(dir, SynthRig::kDome, 3);
  const std::vector<BrdfSample> samples = ReadSamples(samples_path);
  const nlohmann::json lights = WriteLightPhotos(samples_path, CollectPhotoStats(samples), dir / "out");
  ASSERT_TRUE(lights.is_array());
  ASSERT_EQ(lights.size(), 3u);
  uint64_t total = 0;
  for (size_t k = 0; k < 3; ++k) {
    const nlohmann::json& light = lights[k];
    EXPECT_EQ(light["id"], "D0" + std::to_string(k));
    EXPECT_EQ(light["kind"], "point");
    EXPECT_EQ(light["photos"], 1);
    EXPECT_EQ(light["photo"], static_cast<int>(k));
    EXPECT_GT(light["samples"].get<uint64_t>(), 100u);
    EXPECT_GT(light["phase_deg"].get<double>(), 0.0);
    total += light["samples"].get<uint64_t>();
    ASSERT_FALSE(light["file"].get<std::string>().empty());
    EXPECT_TRUE(fs::is_regular_file(fs::path(dir / "out") / light["file"].get<std::string>()));
  }
  EXPECT_EQ(total, samples.size());
}

TEST(LightPhotos, OneLightSessionHasNoLightsBlock) {
  ScratchDir dir;
  const std::string samples_path = Derendered(dir, SynthRig::kArc, 2);
  const nlohmann::json lights =
      WriteLightPhotos(samples_path, CollectPhotoStats(ReadSamples(samples_path)), dir / "out");
  EXPECT_TRUE(lights.is_null());
}

}  // namespace
}  // namespace ibrdf
