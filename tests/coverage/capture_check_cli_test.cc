// `ibrdf capture check` through the command line: the per-photo lines, the predicted coverage, the
// suggestions in capture-check.json (and that `ibrdf synth --camera-positions` renders them), and the
// error for a session without poses.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/session.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

std::string Material() { return std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json"; }

TEST(CaptureCheckCli, SuggestsPhotosThatAddCoverage) {
  ScratchDir dir;
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + Material() +
                                   " --photos 3 --width 200 --height 150 --effects none");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const RunResult check = RunIbrdf("capture check " + dir / "s" + " --suggest 2 --samples-per-view 4000 --out " +
                                   dir / "cc", /*quiet=*/true);
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("photo photos/000.exr: pose yes"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("predicted coverage: measured"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("suggestion 2: camera at"), std::string::npos) << check.output;
  const nlohmann::json report = ReadJsonFile(dir / "cc/capture-check.json");
  EXPECT_EQ(report["format"], "ibrdf-capture-check");
  ASSERT_EQ(report["suggestions"].size(), 2u);
  EXPECT_EQ(report["photos"].size(), 3u);
  const double before = report["coverage_before"]["measured_fraction"];
  const double after = report["coverage_after"]["measured_fraction"];
  EXPECT_GT(after, before + 0.05) << before << " -> " << after;
  const ImageSpec png = ReadImageSpec(dir / "cc/coverage.png");
  EXPECT_EQ(png.width, 2 * 360 + 8);
  EXPECT_EQ(png.height, 360);
  // The suggested photos rendered after the session's own: 5 photos, the last two at the suggestions.
  const RunResult more = RunIbrdf("synth --out " + dir / "s5" + " --material " + Material() +
                                  " --photos 3 --width 200 --height 150 --effects none --camera-positions " +
                                  dir / "cc/capture-check.json");
  ASSERT_EQ(more.exit_code, 0) << more.output;
  const Session session = Session::Load(dir / "s5");
  ASSERT_EQ(session.photos.size(), 5u);
  for (int n = 0; n < 2; ++n) {
    const nlohmann::json& p = report["suggestions"][n]["position"];
    const Eigen::Vector3d expected(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    const Eigen::Vector3d centre = session.photos[3 + n].camera_from_world->Inverse().translation;
    EXPECT_NEAR((centre - expected).norm(), 0.0, 1e-9);
  }
  // The suggestions' predicted coverage is what capture check then predicts of the rendered session.
  const RunResult again = RunIbrdf("capture check " + dir / "s5" + " --suggest 0 --samples-per-view 4000 --out " +
                                   dir / "cc5");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const double rendered = ReadJsonFile(dir / "cc5/capture-check.json")["coverage_before"]["measured_fraction"];
  EXPECT_NEAR(rendered, after, 0.01);
}

TEST(CaptureCheckCli, SessionWithoutPosesIsAnError) {
  ScratchDir dir;
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + Material() +
                                   " --photos 2 --width 96 --height 72 --effects none");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  nlohmann::json manifest = ReadJsonFile(dir / "s/session.json");
  for (auto& photo : manifest["photos"]) photo.erase("camera_from_world");
  std::ofstream(dir / "s/session.json") << manifest.dump(2);
  const RunResult check = RunIbrdf("capture check " + dir / "s", /*quiet=*/true);
  EXPECT_NE(check.exit_code, 0);
  EXPECT_NE(check.output.find("missing: photo photos/000.exr: no camera_from_world"), std::string::npos)
      << check.output;
  EXPECT_NE(check.output.find("ibrdf align"), std::string::npos) << check.output;
}

}  // namespace
}  // namespace ibrdf
