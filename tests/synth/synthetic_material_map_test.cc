// Rendering a spatially varying sample (synthetic.h with a MaterialMap): every hit's BRDF is the map's
// at its world point. Lambertian stripes under one point light make the check exact: the radiance with
// the map, divided by the radiance of a white (albedo 1) Lambertian sample seen by the same ray, is the
// map's albedo at the hit, w(x) . albedo.
#include <algorithm>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/math.h"
#include "core/session.h"
#include "derender/analytic_sample.h"
#include "synth/material_map.h"
#include "synth/pixel_rays.h"
#include "synth/synthetic.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

constexpr double kDark = 0.2, kBright = 0.7;

// Eight stripes about the vertical axis through the sphere's centre, alternating dark and bright; the
// boundaries after stripes 0 and 4 blend over 15 mm, the others are sharp.
MaterialMap EightStripes() {
  std::vector<std::shared_ptr<const BrdfModel>> materials = {
      std::make_shared<LambertianBrdf>(Eigen::Vector3d::Constant(kDark)),
      std::make_shared<LambertianBrdf>(Eigen::Vector3d::Constant(kBright))};
  return MaterialMap({"dark", "bright"}, materials, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(),
                     {0, 1, 0, 1, 0, 1, 0, 1}, {0.015, 0, 0, 0, 0.015, 0, 0, 0}, "eight stripes");
}

SynthOptions SmallSphere() {
  SynthOptions options;
  options.rig.num_photos = 3;
  options.rig.width = 240;
  options.rig.height = 180;
  options.rig.camera_elevation_deg = 20.0;  // the stripes seen slanting, not edge on
  options.effects = CameraEffects::None();
  return options;
}

TEST(SynthMaterialMap, EachPixelHasTheMapsAlbedoAtItsHit) {
  ScratchDir dir;
  const MaterialMap map = EightStripes();
  const SynthSummary summary = WriteSyntheticSession(SmallSphere(), map, "eight-stripes.json", dir / "s", false);
  ASSERT_TRUE(summary.success);
  const Session session = Session::Load(dir / "s/session.json");
  const std::unique_ptr<AnalyticSample> sphere = AnalyticSample::Create(session.sample);
  const LambertianBrdf white(Eigen::Vector3d::Ones());
  const PixelRays rays(session.camera, 1);
  int pure[2] = {0, 0}, blended = 0, checked = 0;
  double ratio_sum[2] = {0.0, 0.0};
  for (size_t photo = 0; photo < session.photos.size(); ++photo) {
    std::vector<uint8_t> mask;
    const Image with_map = RenderRadiance(session, photo, *sphere, false, map, 1, &mask);
    const Image reference = RenderRadiance(session, photo, *sphere, false, white, 1, nullptr);
    const CameraRay camera(session.camera, *session.photos[photo].camera_from_world);
    double peak = 0.0;
    for (float v : reference.pixels) peak = std::max(peak, double(v));
    for (int y = 0; y < with_map.height; ++y) {
      for (int x = 0; x < with_map.width; ++x) {
        const double lit = reference.at(x, y, 0);
        if (!mask[size_t(y) * with_map.width + x] || lit < 0.05 * peak) continue;
        // The hit the renderer shaded: the pixel centre's ray (the same undistorted camera-plane point).
        SurfaceHit hit;
        ASSERT_TRUE(sphere->Intersect(camera.eye(), camera.DirectionOfCamPlane(rays.CamPlane(x, y, 0, 0)), &hit));
        const Eigen::VectorXd w = map.Weights(hit.point);
        const bool mixed = w.minCoeff() > 1e-9;
        // A pure point within half a millimetre of a sharp boundary might lie across it for a ray a
        // rounding error away; every other point's albedo is continuous in the point.
        if (!mixed && map.BoundaryDistance(hit.point) < 5e-4) continue;
        const double expected = w[0] * kDark + w[1] * kBright;
        for (int c = 0; c < 3; ++c) {
          ASSERT_NEAR(with_map.at(x, y, c) / reference.at(x, y, c), expected, 1e-5 * expected)
              << "photo " << photo << " pixel " << x << "," << y;
        }
        ++checked;
        if (w.minCoeff() > 0.1) {
          // Well inside a blend: between the two stripes' values, and not at either.
          ++blended;
          EXPECT_GT(with_map.at(x, y, 0) / lit, kDark + 0.09 * (kBright - kDark));
          EXPECT_LT(with_map.at(x, y, 0) / lit, kBright - 0.09 * (kBright - kDark));
        } else if (!mixed && map.BoundaryDistance(hit.point) > 5e-3) {
          const int label = map.Label(hit.point);
          ++pure[label];
          ratio_sum[label] += with_map.at(x, y, 0) / lit;
        }
      }
    }
  }
  EXPECT_GT(checked, 5000);
  ASSERT_GT(pure[0], 500);
  ASSERT_GT(pure[1], 500);
  EXPECT_GT(blended, 100);
  // Well inside the stripes: each stripe's albedo, and their ratio the albedos' within 1 %.
  const double dark = ratio_sum[0] / pure[0], bright = ratio_sum[1] / pure[1];
  EXPECT_NEAR(dark, kDark, 1e-3);
  EXPECT_NEAR(bright, kBright, 1e-3);
  EXPECT_NEAR((bright / dark) / (kBright / kDark), 1.0, 0.01);
}

TEST(SynthMaterialMap, TruthHoldsTheMapInPlaceOfOneMaterial) {
  ScratchDir dir;
  const MaterialMap map = EightStripes();
  ASSERT_TRUE(WriteSyntheticSession(SmallSphere(), map, "eight-stripes.json", dir / "s", false).success);
  const nlohmann::json truth = ReadJsonFile(dir / "s/truth.json");
  EXPECT_FALSE(truth.contains("material"));  // no one material is the truth
  EXPECT_EQ(truth.at("material_map_name"), "eight-stripes.json");
  const MaterialMap back = MaterialMap::FromJson(truth.at("material_map"), "truth.json");
  ASSERT_EQ(back.NumMaterials(), 2u);
  for (double deg = 1.0; deg < 360.0; deg += 3.7) {
    const Eigen::Vector3d p(0.04 * std::cos(deg * kDegree), 0.04 * std::sin(deg * kDegree), 0.01);
    EXPECT_NEAR((back.Weights(p) - map.Weights(p)).norm(), 0.0, 1e-12) << deg;
  }
}

}  // namespace
}  // namespace ibrdf
