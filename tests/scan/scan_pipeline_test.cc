// The scan stage end to end: synthetic range scans and unorganized points through every step, the
// outputs and their sidecar, and the bunny merged with its .conf.
#include "scan/scan_pipeline.h"

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "scan/ply_io.h"
#include "scan/synthetic_scan.h"
#include "tests/scan/scan_test_util.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::AngleBetween;
using testing::Median;
using testing::ScratchDir;

TEST(ScanPipeline, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ScanOptions().Check(&why)) << why;
  EXPECT_FALSE(ScanSummary().success);
}

TEST(ScanPipeline, UnorganizedPointsReconstructedEndToEnd) {
  SetVerbosity(0);
  ScratchDir dir;
  SyntheticRangeScanOptions synth;
  synth.cols = synth.rows = 80;
  WritePly(dir / "sphere.ply", MakeSyntheticRangeScan(synth));
  ScanResult result = RunScan({{dir / "sphere.ply", std::nullopt}}, ScanOptions());
  // A point cloud without faces: CGAL reconstructed it.
  EXPECT_GT(result.summary.reconstructed_faces, result.mesh.points.size());
  EXPECT_TRUE(result.summary.success);
  ASSERT_EQ(result.mesh.normals.size(), result.mesh.points.size());
  std::vector<double> errors;
  for (size_t i = 0; i < result.mesh.points.size(); ++i) {
    ASSERT_TRUE(result.mesh.normals[i].allFinite());
    if (result.mesh.fit_neighbours[i] > 0) {
      errors.push_back(AngleBetween(result.mesh.normals[i], TrueEllipsoidNormal(synth, result.mesh.points[i])));
    }
  }
  EXPECT_GT(errors.size(), 0.98 * result.mesh.points.size());
  EXPECT_LT(Median(errors), 1.0 * M_PI / 180);
  EXPECT_FALSE(result.summary.convexity.needs_shadow_rays) << result.summary.convexity.BriefReport();

  WriteScanOutputs(dir / "out.ply", result, ScanOptions());
  const ScanMesh back = ReadPly(dir / "out.ply");
  EXPECT_EQ(back.points.size(), result.mesh.points.size());
  EXPECT_EQ(back.faces.size(), result.mesh.faces.size());
  std::ifstream in(ScanSidecarPath(dir / "out.ply"));
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("convexity").at("needs_shadow_rays"), false);
  EXPECT_GT(sidecar.at("convexity").at("fraction_within_tolerance").get<double>(), 0.99);
  EXPECT_EQ(sidecar.at("points"), result.mesh.points.size());
}

TEST(ScanPipeline, NothingLeftIsAnError) {
  SetVerbosity(0);
  ScratchDir dir;
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  mesh.faces = {{0, 1, 2}};  // collinear: degenerate
  WritePly(dir / "line.ply", mesh);
  EXPECT_THROW(RunScan({{dir / "line.ply", std::nullopt}}, ScanOptions()), Error);
  EXPECT_THROW(RunScan({}, ScanOptions()), Error);
}

TEST(ScanPipeline, BunnyMergedWithConf) {
  IBRDF_REQUIRE_BUNNY();
  SetVerbosity(0);
  const std::vector<ScanInput> inputs = InputsFromConf(
      testing::BunnyDir() + "/bun.conf", {testing::BunnyDir() + "/bun000.ply", testing::BunnyDir() + "/bun045.ply"});
  const ScanResult result = RunScan(inputs, ScanOptions());
  EXPECT_EQ(result.summary.inputs.size(), 2u);
  EXPECT_EQ(result.summary.inputs[0].kind, "range grid");
  EXPECT_GT(result.mesh.points.size(), 70000u);
  EXPECT_GT(result.summary.normals.fitted, 0.98 * result.mesh.points.size());
  EXPECT_LT(result.summary.normals.rms_median_m, 0.2e-3);
  // The bunny (ears, the neck) is far from convex.
  EXPECT_TRUE(result.summary.convexity.needs_shadow_rays);
}

}  // namespace
}  // namespace ibrdf
