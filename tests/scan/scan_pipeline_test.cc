// The scan stage end to end: synthetic range scans and unorganized points through every step, the
// outputs and their sidecar, and the bunny merged with its .conf.
#include "scan/scan_pipeline.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/session.h"
#include "scan/ply_io.h"
#include "synth/synthetic_scan.h"
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

// A session folder whose mesh sample lists `scan_inputs` (one photo file, never opened).
void WriteMeshSession(const ScratchDir& dir, const nlohmann::json& scan_inputs) {
  testing::WriteText(dir / "photo.png", "not read");
  const nlohmann::json manifest = {
      {"format", "ibrdf-session"},
      {"version", 1},
      {"camera", {{"model", "PINHOLE"}, {"width", 8}, {"height", 6}, {"params", {10.0, 10.0, 4.0, 3.0}}}},
      {"light", {{"kind", "point"}, {"position", {0.0, 0.0, 1.0}}, {"intensity", {1.0, 1.0, 1.0}}}},
      {"sample", {{"kind", "mesh"}, {"file", "mesh.ply"}, {"scan_inputs", scan_inputs}}},
      {"photos", {{{"file", "photo.png"}, {"exposure_s", 1.0}}}}};
  testing::WriteText(dir / "session.json", manifest.dump(2));
}

// The session's scan inputs reach the pipeline as they are, one type: absolute files and transforms.
TEST(ScanPipeline, InputsFromSessionCarryFilesAndTransforms) {
  ScratchDir dir;
  WriteMeshSession(dir,
                   {"a.ply",
                    {{"file", "sub/b.ply"},
                     {"world_from_scan", {{"rotation", {0.0, 0.0, 0.0, 1.0}}, {"translation", {0.0, 0.0, 0.1}}}}}});
  const Session session = Session::Load(dir / "session.json");
  const std::vector<ScanInputSpec> inputs = InputsFromSession(session);
  ASSERT_EQ(inputs.size(), 2u);
  EXPECT_EQ(inputs[0].file, session.AbsolutePath("a.ply"));
  EXPECT_TRUE(std::filesystem::path(inputs[1].file).is_absolute());
  EXPECT_EQ(inputs[1].file, session.AbsolutePath("sub/b.ply"));
  EXPECT_FALSE(inputs[0].world_from_scan.has_value());
  ASSERT_TRUE(inputs[1].world_from_scan.has_value());
  EXPECT_EQ(inputs[1].world_from_scan->translation, Eigen::Vector3d(0.0, 0.0, 0.1));
  EXPECT_NEAR(inputs[1].world_from_scan->rotation.z(), 1.0, 1e-15);

  std::vector<std::string> read;
  EXPECT_EQ(ResolveScanInputs({{}, "", dir / "session.json"}, &read).size(), 2u);
  EXPECT_EQ(read.front(), dir / "session.json");
  EXPECT_THROW(ResolveScanInputs({{"x.ply"}, "", dir / "session.json"}, &read), Error);
  EXPECT_THROW(ResolveScanInputs({{}, dir / "a.conf", dir / "session.json"}, &read), Error);
  EXPECT_THROW(ResolveScanInputs({}, &read), Error);
}

// A sphere sample, or a mesh without scans, has nothing to scan: an Error naming the manifest's field.
TEST(ScanPipeline, InputsFromSessionWithoutScansIsAnError) {
  ScratchDir dir;
  WriteMeshSession(dir, nlohmann::json::array());
  try {
    InputsFromSession(Session::Load(dir / "session.json"));
    ADD_FAILURE() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir / "session.json: /sample/scan_inputs"), std::string::npos) << e.what();
  }
}

// The transform of a session's scan moves the merged mesh like the same scan read without it, shifted.
TEST(ScanPipeline, SessionTransformAppliedToTheScan) {
  SetVerbosity(0);
  ScratchDir dir;
  SyntheticRangeScanOptions synth;
  synth.cols = synth.rows = 60;
  WritePly(dir / "sphere.ply", MakeSyntheticRangeScan(synth));
  WriteMeshSession(dir,
                   {{{"file", "sphere.ply"},
                     {"world_from_scan", {{"rotation", {1.0, 0.0, 0.0, 0.0}}, {"translation", {0.0, 0.0, 0.25}}}}}});
  const ScanResult plain = RunScan({{dir / "sphere.ply", std::nullopt}}, ScanOptions());
  const ScanResult moved = RunScan(InputsFromSession(Session::Load(dir / "session.json")), ScanOptions());
  ASSERT_EQ(moved.mesh.points.size(), plain.mesh.points.size());
  for (size_t i = 0; i < plain.mesh.points.size(); i += 97) {
    EXPECT_LT((moved.mesh.points[i] - plain.mesh.points[i] - Eigen::Vector3d(0.0, 0.0, 0.25)).norm(), 1e-12);
  }
}

TEST(ScanPipeline, BunnyMergedWithConf) {
  IBRDF_REQUIRE_BUNNY();
  SetVerbosity(0);
  const std::vector<ScanInputSpec> inputs = InputsFromConf(
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
