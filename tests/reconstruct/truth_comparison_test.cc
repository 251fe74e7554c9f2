// Truth comparison: known relative errors come out as such, per channel and per theta band.
#include "reconstruct/truth_comparison.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/truth_file.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

BrdfSample MakeSample(double theta_i, double theta_e, double delta_phi, const Eigen::Vector3d& f) {
  Eigen::Vector3d wi, wo;
  FromIsotropic({theta_i, theta_e, delta_phi}, &wi, &wo);
  BrdfSample s{};
  for (int c = 0; c < 3; ++c) {
    s.wi[c] = float(wi[c]);
    s.wo[c] = float(wo[c]);
    s.brdf[c] = float(f[c]);
  }
  s.theta_i = float(theta_i);
  s.theta_e = float(theta_e);
  s.delta_phi = float(delta_phi);
  return s;
}

TEST(TruthComparison, KnownScaleErrorsPerChannel) {
  const LambertianBrdf truth(Eigen::Vector3d(0.2, 0.4, 0.6));
  std::vector<BrdfSample> samples;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d f = truth.albedo() / M_PI;
    samples.push_back(MakeSample(0.01 * i, 0.5, 1.0, f.cwiseProduct(Eigen::Vector3d(1.01, 0.98, 1.0))));
  }
  const TruthComparison comparison = CompareWithTruth(samples, truth);
  ASSERT_EQ(comparison.overall.count, 100u);
  EXPECT_NEAR(comparison.overall.median[0], 0.01, 1e-6);
  EXPECT_NEAR(comparison.overall.median[1], 0.02, 1e-6);
  EXPECT_NEAR(comparison.overall.median[2], 0.0, 1e-6);
  EXPECT_NEAR(comparison.overall.bias[1], -0.02, 1e-6);
}

TEST(TruthComparison, BandsByLargerTheta) {
  const LambertianBrdf truth(Eigen::Vector3d::Constant(0.5));
  const Eigen::Vector3d exact = truth.albedo() / M_PI;
  std::vector<BrdfSample> samples = {
      MakeSample(0.1, 0.1, 0.0, exact),                        // 0-20 band, exact
      MakeSample(0.1, 75.0 * M_PI / 180.0, 0.0, 1.1 * exact),  // 70-80 band, 10 % high
  };
  const TruthComparison comparison = CompareWithTruth(samples, truth);
  ASSERT_EQ(comparison.bands.size(), 6u);
  EXPECT_EQ(comparison.bands[0].stats.count, 1u);
  EXPECT_NEAR(comparison.bands[0].stats.median[0], 0.0, 1e-6);
  EXPECT_EQ(comparison.bands[4].stats.count, 1u);
  EXPECT_NEAR(comparison.bands[4].stats.median[0], 0.1, 1e-6);
}

TEST(TruthComparison, ZeroTruthIsSkippedNotDividedBy) {
  const LafortuneBrdf truth(Eigen::Vector3d::Zero(), {{Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1),
                                                       Eigen::Vector3d::Constant(50)}});
  // In the retro-reflection direction at theta = 1 rad the lobe's base cos(2) is negative: f is exactly 0.
  std::vector<BrdfSample> samples = {MakeSample(1.0, 1.0, 0.0, Eigen::Vector3d::Constant(0.1))};
  const TruthComparison comparison = CompareWithTruth(samples, truth);
  EXPECT_EQ(comparison.skipped_zero_truth, 1u);
  EXPECT_EQ(comparison.overall.count, 0u);
  EXPECT_TRUE(comparison.overall.median.allFinite());
}

// truth.json's format and version are checked: an unknown version is an Error naming the file and field.
TEST(TruthComparison, LoadTruthMaterialRejectsUnknownVersions) {
  testing::ScratchDir dir;
  auto write = [&](const std::string& name, const std::string& format, int version) {
    std::ofstream(dir / name) << "{\"format\": \"" << format << "\", \"version\": " << version
                              << ", \"material_name\": \"grey\", \"generator\": {}, "
                                 "\"material\": {\"model\": \"lambertian\", \"albedo\": [0.5, 0.5, 0.5]}}";
    return dir / name;
  };
  EXPECT_NO_THROW(LoadTruthMaterial(write("v1.json", "ibrdf-truth", 1)));
  const std::string v2 = write("v2.json", "ibrdf-truth", 2);
  try {
    LoadTruthMaterial(v2);
    ADD_FAILURE() << "version 2 was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(v2), std::string::npos) << message;
    EXPECT_NE(message.find("version"), std::string::npos) << message;
  }
  EXPECT_THROW(LoadTruthMaterial(write("v0.json", "ibrdf-truth", 0)), Error);
  EXPECT_THROW(LoadTruthMaterial(write("other.json", "ibrdf-alignment", 1)), Error);
}

// A spatially varying truth (synth --material-map) has no one material: every single-material reader
// says so, naming the file and the field, rather than picking a basis material.
TEST(TruthComparison, SpatiallyVaryingTruthIsRefusedNamingTheField) {
  testing::ScratchDir dir;
  const std::string path = dir / "truth.json";
  std::ofstream(path) << R"({"format": "ibrdf-truth", "version": 1, "material_map_name": "map.json",
    "generator": {}, "material_map": {"kind": "stripes", "centre": [0, 0, 0], "axis": [0, 0, 1],
    "materials": [{"name": "a", "material": {"model": "lambertian", "albedo": [0.2, 0.2, 0.2]}},
                  {"name": "b", "material": {"model": "lambertian", "albedo": [0.7, 0.7, 0.7]}}],
    "stripes": [0, 1], "blend_mm": [0, 10]}})";
  EXPECT_TRUE(IsSpatiallyVaryingTruth(path));
  for (const auto& load : {LoadTruthMaterial, LoadTruthFile}) {
    try {
      load(path);
      ADD_FAILURE() << "a spatially varying truth was read as one material";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path + ": /material_map"), std::string::npos) << message;
      EXPECT_NE(message.find(kSpatiallyVaryingTruth), std::string::npos) << message;
    }
  }
  std::ofstream(dir / "one.json") << R"({"format": "ibrdf-truth", "version": 1, "generator": {},
    "material": {"model": "lambertian", "albedo": [0.5, 0.5, 0.5]}})";
  EXPECT_FALSE(IsSpatiallyVaryingTruth(dir / "one.json"));
  EXPECT_FALSE(IsSpatiallyVaryingTruth(dir / "table.binary"));  // by extension, not read
}

}  // namespace
}  // namespace ibrdf
