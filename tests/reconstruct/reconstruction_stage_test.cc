// The reconstruct stage (reconstruct/reconstruction_stage.h) through its library call: bandwidth
// selection by GCV (curve and selected radii in summary.json, the curve in the log), the files of a
// full run, option checks that name the failing constraint, and no samples refused with nothing written.
#include "reconstruct/reconstruction_stage.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/npy.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::MaterialPath;
using testing::ScratchDir;

using testing::ErrorOf;

// One small session (bluepaint, 6 photos of 200 x 150), rendered and derendered once for the suite.
class ReconstructionStage : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // ScratchDir needs a running test; the suite's folder is made by hand.
    dir_ = (fs::temp_directory_path() / ("ibrdf-ReconstructionStage-" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    SetVerbosity(0);
    SynthOptions synth;
    synth.rig.num_photos = 6;
    synth.rig.width = 200;
    synth.rig.height = 150;
    const std::string session = dir_ + "/session";
    testing::MakeSession(session, synth, *LoadMaterial(MaterialPath("bluepaint")));
    samples_ = new std::vector<BrdfSample>(Derender(Session::Load(session), DerenderOptions()).samples);
    truth_ = session + "/truth.json";
    // A few evaluation points (theta_i, theta_e, delta_phi), so the tests skip the full MERL table.
    points_ = dir_ + "/points.npy";
    WriteNpyArray(points_, std::vector<double>{0.3, 0.5, 3.0, 0.6, 0.6, 2.5, 0.2, 0.9, 3.1}, {3, 3});
  }
  static void TearDownTestSuite() {
    delete samples_;
    fs::remove_all(dir_);
  }
  // Evaluation at the points only, scored against the truth.
  static ReconstructOptions EvalOnly() {
    ReconstructOptions options;
    options.truth_file = truth_;
    options.eval_file = points_;
    options.eval_only = true;
    return options;
  }
  ScratchDir out_dir_;
  static std::string dir_, truth_, points_;
  static std::vector<BrdfSample>* samples_;
};
std::string ReconstructionStage::dir_, ReconstructionStage::truth_, ReconstructionStage::points_;
std::vector<BrdfSample>* ReconstructionStage::samples_ = nullptr;

TEST(ReconstructOptions, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(ReconstructOptions().Check(&why)) << why;
}

TEST(ReconstructOptions, CheckNamesTheFailingConstraint) {
  ReconstructOptions options;
  options.eval_only = true;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("eval_file"), std::string::npos) << why;
  options = ReconstructOptions();
  options.selection.scales = {0.0, 1.0};
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why.rfind("selection: ", 0), 0u) << why;
  options = ReconstructOptions();
  options.regression.degree = 3;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why.rfind("regression: ", 0), 0u) << why;
}

TEST_F(ReconstructionStage, SelectsTheBandwidthByGcv) {
  const std::string out = out_dir_ / "rec";
  ReconstructOptions options = EvalOnly();
  options.select_bandwidth = true;
  options.selection.criterion = BandwidthCriterion::kGeneralizedCrossValidation;
  options.selection.scales = {0.7, 1.4};
  options.selection.samples = 400;
  SetVerbosity(1);
  ::testing::internal::CaptureStderr();
  const ReconstructResult result = Reconstruct(*samples_, options, out, "samples.npy");
  const std::string log = ::testing::internal::GetCapturedStderr();
  SetVerbosity(0);
  ASSERT_TRUE(result.success);
  EXPECT_NE(log.find("bandwidth criterion curve (gcv)"), std::string::npos) << log;
  std::ifstream in(out + "/summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary, result.summary);
  EXPECT_EQ(summary.at("samples_file"), "samples.npy");
  EXPECT_EQ(summary.at("regression").at("bandwidth"), "gcv");
  const nlohmann::json& selection = summary.at("bandwidth_selection");
  EXPECT_EQ(selection.at("criterion"), "gcv");
  ASSERT_EQ(selection.at("curve").size(), 2u);
  const double rh = summary.at("regression").at("radius_h_deg");
  EXPECT_TRUE(rh == 2.5 * 0.7 || rh == 2.5 * 1.4) << rh;
  EXPECT_EQ(rh, selection.at("selected_radius_h_deg").get<double>());
  EXPECT_EQ(rh, result.regression.radius_h_deg);
  for (const nlohmann::json& c : selection.at("curve")) {
    EXPECT_GT(c.at("gcv_rms").get<double>(), 0.0);
    EXPECT_GT(c.at("mean_leverage").get<double>(), 0.0);
  }
  EXPECT_EQ(result.eval_points, 3u);
  EXPECT_TRUE(fs::exists(out + "/eval.npy"));
  EXPECT_TRUE(fs::exists(out + "/eval_truth.npy"));
  EXPECT_FALSE(fs::exists(out + "/brdf.binary"));
}

TEST_F(ReconstructionStage, EvaluatesAtThePointsNearTheTruth) {
  const std::string out = out_dir_ / "rec";
  const ReconstructResult result = Reconstruct(*samples_, EvalOnly(), out);
  ASSERT_TRUE(result.success);
  EXPECT_EQ(result.summary.at("regression").at("bandwidth"), "given");
  EXPECT_EQ(result.samples, samples_->size());
  EXPECT_GT(result.samples_used, 0u);
  std::vector<size_t> shape, truth_shape;
  const std::vector<double> values = ReadNpyArray(out + "/eval.npy", &shape);
  const std::vector<double> truth = ReadNpyArray(out + "/eval_truth.npy", &truth_shape);
  ASSERT_EQ(shape, (std::vector<size_t>{3, 3}));
  ASSERT_EQ(truth_shape, shape);
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] < 0.0) continue;  // unsupported
    EXPECT_NEAR(values[i], truth[i], 0.2 * truth[i]) << i;
  }
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The stage runs the fits beside the tabulation, and the score and the table's files beside the .bsdf
// export (docs/decisions.md, "Reconstruct speed"): on one thread and on two every file is the same,
// byte for byte, and the summary's figures too (timings and the merged mean of effective samples,
// whose float sum depends on the order the parallel chunks finish in, left out).
TEST_F(ReconstructionStage, OneAndTwoThreadsWriteTheSameFiles) {
  ReconstructOptions options;
  options.truth_file = truth_;
  options.tabulate.max_theta_deg = 40.0;  // a part of the table, to keep the test short
  options.fit.max_samples = 1500;
  options.fit.max_iterations = 50;
  options.bsdf_export.theta_i_count = 4;
  options.bsdf_export.ndf_size = 32;
  options.bsdf_export.vndf_size = 16;
  options.bsdf_export.rgb_size = 16;
  options.name = "bluepaint";
  std::vector<ReconstructResult> results;
  for (int threads : {1, 2}) {
    tbb::global_control control(tbb::global_control::max_allowed_parallelism, size_t(threads));
    results.push_back(Reconstruct(*samples_, options, out_dir_ / ("rec" + std::to_string(threads))));
    ASSERT_TRUE(results.back().success);
  }
  const std::string one = out_dir_ / "rec1", two = out_dir_ / "rec2";
  for (const char* file : {"brdf.binary", "brdf.npy", "domain.npy", "effective_samples.npy", "brdf.json",
                           "lafortune.json", "ggx.json", "bluepaint.bsdf", "bluepaint.pbrt", "bluepaint.xml"}) {
    SCOPED_TRACE(file);
    ASSERT_TRUE(fs::exists(one + "/" + file));
    EXPECT_EQ(FileBytes(one + "/" + file), FileBytes(two + "/" + file));
  }
  nlohmann::json a = results[0].summary, b = results[1].summary;
  for (nlohmann::json* summary : {&a, &b}) {
    summary->erase("timings_s");
    summary->at("regression").at("reliability").erase("mean_effective_samples");
    summary->at("bsdf").erase("build_s");
    summary->at("fits").at("lafortune").erase("seconds");
    summary->at("fits").at("ggx").erase("seconds");
  }
  EXPECT_EQ(a, b) << nlohmann::json::diff(a, b).dump(1);
  EXPECT_TRUE(a.contains("fits") && a.contains("error_against_truth") && a.contains("merl_lookups_against_truth"));
  EXPECT_GT(a.at("error_against_truth").at("cells_scored").get<double>(), 1000.0);
  EXPECT_GT(results[0].summary.at("timings_s").at("score_s").get<double>(), 0.0);
  EXPECT_EQ(results[0].chosen_model, results[1].chosen_model);
}

TEST_F(ReconstructionStage, NoSamplesIsAnErrorAndWritesNothing) {
  const std::string out = out_dir_ / "rec";
  const std::string message = ErrorOf([&] { Reconstruct({}, EvalOnly(), out, "empty.npy"); });
  EXPECT_NE(message.find("empty.npy: holds no samples"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(ReconstructionStage, BadOptionsAreAnErrorNamingTheConstraint) {
  ReconstructOptions options;
  options.eval_only = true;
  const std::string message = ErrorOf([&] { Reconstruct(*samples_, options, out_dir_ / "rec"); });
  EXPECT_NE(message.find("reconstruct options: "), std::string::npos) << message;
  EXPECT_NE(message.find("eval_file"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out_dir_ / "rec"));
}

}  // namespace
}  // namespace ibrdf
