// `ibrdf scan` as a user meets it: a clean run with a summary, and bad input answered with a clear
// message naming the file, a non-zero exit, and nothing written.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "scan/ply_io.h"
#include "synth/synthetic_scan.h"
#include "tests/run_ibrdf.h"
#include "tests/scan/scan_test_util.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
using testing::WriteText;
namespace fs = std::filesystem;

std::string SphereMesh(const ScratchDir& dir) {
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.05, 0.05), 40, 80);
  mesh.normals.clear();
  WritePly(dir / "sphere.ply", mesh);
  return dir / "sphere.ply";
}

TEST(ScanCommand, WritesMeshSidecarAndSummary) {
  ScratchDir dir;
  const std::string input = SphereMesh(dir);
  const RunResult run = RunIbrdf("scan " + input + " --out " + dir / "out.ply", /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("Scan summary"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("convex, no shadow rays needed"), std::string::npos) << run.output;
  const ScanMesh out = ReadPly(dir / "out.ply");
  EXPECT_EQ(out.normals.size(), out.points.size());
  std::ifstream in(dir / "out.ply.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("convexity").at("needs_shadow_rays"), false);
  // An existing output needs --overwrite; an input is never an output.
  EXPECT_NE(RunIbrdf("scan " + input + " --out " + dir / "out.ply").exit_code, 0);
  EXPECT_EQ(RunIbrdf("scan " + input + " --out " + dir / "out.ply --overwrite").exit_code, 0);
  const RunResult self = RunIbrdf("scan " + input + " --out " + input + " --overwrite");
  EXPECT_NE(self.exit_code, 0);
  EXPECT_NE(self.output.find("is an input"), std::string::npos) << self.output;
}

TEST(ScanCommand, BadInputExitsNonZeroNamingTheFile) {
  ScratchDir dir;
  WriteText(dir / "empty.ply", "");
  WriteText(
      dir / "truncated.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "0 0 0\n1 0 0\n");
  WriteText(
      dir / "lying.ply",
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n");
  WriteText(
      dir / "nan.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
      "0 0 0\n1 NaN 0\n0 1 0\n");
  for (const char* name : {"empty.ply", "truncated.ply", "lying.ply", "nan.ply", "missing.ply"}) {
    const RunResult run = RunIbrdf("scan " + dir / name + " --out " + dir / "out.ply");
    EXPECT_EQ(run.exit_code, 1) << name << ": " << run.output;
    EXPECT_NE(run.output.find("ibrdf: error: " + dir / name), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(dir / "out.ply")) << name;
  }
}

// `ibrdf scan --session`: the session's scan_inputs (with their transforms) are the inputs; a session
// whose sample has no scans is one clear error naming the field.
TEST(ScanCommand, ReadsTheSessionsScanInputs) {
  ScratchDir dir;
  SphereMesh(dir);
  WriteText(dir / "photo.png", "not read");
  nlohmann::json manifest = {
      {"format", "ibrdf-session"},
      {"version", 1},
      {"camera", {{"model", "PINHOLE"}, {"width", 8}, {"height", 6}, {"params", {10.0, 10.0, 4.0, 3.0}}}},
      {"light", {{"kind", "point"}, {"position", {0.0, 0.0, 1.0}}, {"intensity", {1.0, 1.0, 1.0}}}},
      {"sample",
       {{"kind", "mesh"},
        {"file", "mesh.ply"},
        {"scan_inputs",
         {{{"file", "sphere.ply"},
           {"world_from_scan", {{"rotation", {1.0, 0.0, 0.0, 0.0}}, {"translation", {0.0, 0.0, 0.5}}}}}}}}},
      {"photos", {{{"file", "photo.png"}, {"exposure_s", 1.0}}}}};
  WriteText(dir / "session.json", manifest.dump(2));
  const RunResult run = RunIbrdf("scan --session " + dir / "session.json" + " --out " + dir / "out.ply", true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(dir / "out.ply.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  ASSERT_EQ(sidecar.at("inputs").size(), 1u);
  EXPECT_EQ(sidecar.at("inputs")[0].at("path"), fs::absolute(dir / "sphere.ply").lexically_normal().string());
  const ScanMesh out = ReadPly(dir / "out.ply");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : out.points) centroid += p / double(out.points.size());
  EXPECT_NEAR(centroid.z(), 0.5, 1e-3);  // the sphere around the origin, moved by world_from_scan

  const RunResult both = RunIbrdf("scan " + dir / "sphere.ply --session " + dir.str() + " --out " + dir / "x.ply");
  EXPECT_EQ(both.exit_code, 1) << both.output;
  manifest["sample"] = {{"kind", "sphere"}, {"center", {0.0, 0.0, 0.0}}, {"radius", 0.05}};
  WriteText(dir / "session.json", manifest.dump(2));
  const RunResult sphere = RunIbrdf("scan --session " + dir.str() + " --out " + dir / "x.ply");
  EXPECT_EQ(sphere.exit_code, 1);
  EXPECT_NE(sphere.output.find("/sample/kind: the sample is a sphere, not a scanned mesh"), std::string::npos)
      << sphere.output;
  EXPECT_FALSE(fs::exists(dir / "x.ply"));
}

TEST(ScanCommand, BunnyWithConf) {
  IBRDF_REQUIRE_BUNNY();
  ScratchDir dir;
  const std::string bunny = testing::BunnyDir();
  const RunResult run = RunIbrdf("scan " + bunny + "/bun000.ply " + bunny + "/bun045.ply --conf " + bunny +
                                 "/bun.conf --out " + dir / "bunny.ply");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(dir / "bunny.ply.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("inputs").size(), 2u);
  EXPECT_EQ(sidecar.at("convexity").at("needs_shadow_rays"), true);
}

}  // namespace
}  // namespace ibrdf
