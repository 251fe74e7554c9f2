#include "synth/material_map.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/math.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::shared_ptr<const BrdfModel> Grey(double albedo) {
  return std::make_shared<LambertianBrdf>(Eigen::Vector3d::Constant(albedo));
}

// Four stripes about z through the origin: materials 0, 1, 2, 1; the boundary 0|1 (at 90 degrees) is
// blended over 20 mm, the others are sharp.
MaterialMap FourStripes() {
  return MaterialMap({"a", "b", "c"}, {Grey(0.1), Grey(0.5), Grey(0.9)}, Eigen::Vector3d::Zero(),
                     Eigen::Vector3d::UnitZ(), {0, 1, 2, 1}, {0.02, 0.0, 0.0, 0.0}, "four stripes");
}

// The point at azimuth `deg` degrees, `r` metres from the z axis, 1 cm up.
Eigen::Vector3d At(double deg, double r) {
  return Eigen::Vector3d(r * std::cos(deg * kDegree), r * std::sin(deg * kDegree), 0.01);
}

TEST(MaterialMap, StripeCentresArePure) {
  const MaterialMap map = FourStripes();
  EXPECT_EQ(map.Label(At(45, 0.05)), 0);
  EXPECT_EQ(map.Label(At(135, 0.05)), 1);
  EXPECT_EQ(map.Label(At(225, 0.05)), 2);
  EXPECT_EQ(map.Label(At(315, 0.05)), 1);
  EXPECT_NEAR(map.Weights(At(225, 0.05))[2], 1.0, 1e-12);
}

TEST(MaterialMap, BlendIsLinearInArcLengthAndHalfAtTheBoundary) {
  const MaterialMap map = FourStripes();
  const double r = 0.05;
  // 5 mm of arc before the boundary at 90 degrees: a quarter of the weight to the next material.
  const double deg = 90.0 - 0.005 / r / kDegree;
  const Eigen::VectorXd w = map.Weights(At(deg, r));
  EXPECT_NEAR(w[0], 0.75, 1e-9);
  EXPECT_NEAR(w[1], 0.25, 1e-9);
  EXPECT_NEAR(map.Weights(At(90.0 - 1e-9, r))[1], 0.5, 1e-6);
  EXPECT_NEAR(map.Weights(At(90.0 + 1e-9, r))[0], 0.5, 1e-6);
  // The combination's value is the weights' combination of the basis values.
  const Eigen::Vector3d wi(0, 0, 1), wo(0.6, 0, 0.8);
  EXPECT_NEAR(map.Eval(At(deg, r), wi, wo)[0], (0.75 * 0.1 + 0.25 * 0.5) / kPi, 1e-12);
  // Weights stay a convex combination everywhere, the axis included.
  for (double a = 0.0; a < 360.0; a += 7.3) {
    for (double rr : {0.0, 0.001, 0.05}) {
      const Eigen::VectorXd ww = map.Weights(At(a, rr));
      EXPECT_NEAR(ww.sum(), 1.0, 1e-12);
      EXPECT_GE(ww.minCoeff(), 0.0);
    }
  }
}

TEST(MaterialMap, BoundaryDistanceCountsBlendsAndSkipsSameMaterialNeighbours) {
  const MaterialMap map = FourStripes();
  const double r = 0.05;
  // 30 mm of arc before the blended boundary: 20 mm from the blend's edge.
  EXPECT_NEAR(map.BoundaryDistance(At(90.0 - 0.03 / r / kDegree, r)), 0.02, 1e-9);
  EXPECT_EQ(map.BoundaryDistance(At(90.0 - 0.005 / r / kDegree, r)), 0.0);
  // 10 mm past the sharp boundary at 180 degrees.
  EXPECT_NEAR(map.BoundaryDistance(At(180.0 + 0.01 / r / kDegree, r)), 0.01, 1e-9);
  // Stripes 1 and 3 share material 1 with 0 between them only on one side: at 300 degrees the nearest
  // other material is stripe 2's (ending at 270) or stripe 0's (starting at 360, sharp).
  EXPECT_NEAR(map.BoundaryDistance(At(300.0, r)), 30.0 * kDegree * r, 1e-9);
}

TEST(MaterialMap, JsonRoundTripKeepsWeightsAndValues) {
  const MaterialMap map = FourStripes();
  const MaterialMap back = MaterialMap::FromJson(map.ToJson(), "round trip");
  ASSERT_EQ(back.NumMaterials(), 3u);
  EXPECT_EQ(back.Name(2), "c");
  for (double a = 0.0; a < 360.0; a += 11.0) {
    EXPECT_LT((back.Weights(At(a, 0.04)) - map.Weights(At(a, 0.04))).cwiseAbs().maxCoeff(), 1e-12);
  }
  const Eigen::Vector3d wi(0, 0.3, 0.9539), wo(0.2, 0, 0.9798);
  EXPECT_NEAR(back.Eval(At(100, 0.04), wi, wo)[1], map.Eval(At(100, 0.04), wi, wo)[1], 1e-12);
}

TEST(MaterialMap, LoadResolvesMaterialsBesideTheFileAndNamesBadFields) {
  const fs::path dir = fs::temp_directory_path() / "ibrdf_material_map_test";
  fs::create_directories(dir);
  std::ofstream(dir / "grey.json") << R"({"name": "grey", "model": "lambertian", "albedo": [0.5, 0.5, 0.5]})";
  std::ofstream(dir / "map.json") << R"({"kind": "stripes", "centre": [0, 0, 0], "axis": [0, 0, 2],
      "materials": ["grey.json", {"name": "dark", "material": {"model": "lambertian", "albedo": [0.1, 0.1, 0.1]}}],
      "stripes": [0, 1, 0, 1], "blend_mm": 10})";
  const MaterialMap map = MaterialMap::Load((dir / "map.json").string());
  EXPECT_EQ(map.Name(0), "grey");
  EXPECT_EQ(map.Name(1), "dark");
  EXPECT_EQ(map.Label(At(135, 0.05)), 1);
  std::ofstream(dir / "bad.json") << R"({"kind": "stripes", "centre": [0, 0, 0], "axis": [0, 0, 1],
      "materials": ["grey.json"], "stripes": [0, 3], "blend_mm": 0})";
  try {
    MaterialMap::Load((dir / "bad.json").string());
    FAIL() << "a stripe naming material 3 of 1 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("stripe material 3"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "kind.json") << R"({"kind": "checker", "centre": [0, 0, 0], "axis": [0, 0, 1],
      "materials": ["grey.json"], "stripes": [0, 0], "blend_mm": 0})";
  EXPECT_THROW(MaterialMap::Load((dir / "kind.json").string()), Error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ibrdf
