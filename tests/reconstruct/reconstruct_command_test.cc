// `ibrdf reconstruct` as a user meets it: bandwidth selection by GCV end to end (curve and selected
// radii in summary.json), and a bad --bandwidth answered with a clear message, a non-zero exit and
// nothing written.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/npy.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;

// One small session, rendered and derendered once for the suite.
class ReconstructCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ScratchDir needs a running test; the suite's folder is made by hand.
    dir_ =
        (std::filesystem::temp_directory_path() / ("ibrdf-ReconstructCommand-" + std::to_string(::getpid()))).string();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    const std::string session = dir_ + "/session";
    RunResult run = RunIbrdf("synth --out " + session + " --material " + MaterialPath("bluepaint") +
                             " --photos 6 --width 200 --height 150");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    samples_ = dir_ + "/samples.npy";
    run = RunIbrdf("derender " + session + " --out " + samples_);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    truth_ = session + "/truth.json";
    // A few evaluation points (theta_i, theta_e, delta_phi), so the test skips the full MERL table.
    points_ = dir_ + "/points.npy";
    WriteNpyArray(points_, std::vector<double>{0.3, 0.5, 3.0, 0.6, 0.6, 2.5, 0.2, 0.9, 3.1}, {3, 3});
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }
  ScratchDir out_dir_;
  static std::string dir_, samples_, truth_, points_;
};
std::string ReconstructCommand::dir_, ReconstructCommand::samples_, ReconstructCommand::truth_,
    ReconstructCommand::points_;

TEST_F(ReconstructCommand, SelectsTheBandwidthByGcv) {
  const std::string out = out_dir_ / "rec";
  const RunResult run =
      RunIbrdf("reconstruct " + samples_ + " --out " + out + " --truth " + truth_ + " --eval " + points_ +
                   " --eval-only --bandwidth gcv --bandwidth-scales 0.7,1.4" + " --bandwidth-samples 400",
               /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("bandwidth criterion curve (gcv)"), std::string::npos) << run.output;
  std::ifstream in(out + "/summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  const nlohmann::json& selection = summary.at("bandwidth_selection");
  EXPECT_EQ(selection.at("criterion"), "gcv");
  ASSERT_EQ(selection.at("curve").size(), 2u);
  const double rh = summary.at("regression").at("radius_h_deg");
  EXPECT_TRUE(rh == 2.5 * 0.7 || rh == 2.5 * 1.4) << rh;
  EXPECT_EQ(rh, selection.at("selected_radius_h_deg").get<double>());
  for (const nlohmann::json& c : selection.at("curve")) {
    EXPECT_GT(c.at("gcv_rms").get<double>(), 0.0);
    EXPECT_GT(c.at("mean_leverage").get<double>(), 0.0);
  }
}

TEST_F(ReconstructCommand, UnknownBandwidthCriterionIsAClearError) {
  const std::string out = out_dir_ / "rec";
  const RunResult run = RunIbrdf("reconstruct " + samples_ + " --out " + out + " --bandwidth aic");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("--bandwidth"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("aic"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(RunIbrdf("reconstruct " + samples_ + " --out " + out + " --bandwidth loo --bandwidth-scales 0,1").exit_code,
            0);
}

}  // namespace
}  // namespace ibrdf
