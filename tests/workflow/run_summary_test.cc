// Tests of workflow/run_summary.h and stage_json.h: the summary is built from the stages' outputs
// through typed readers; a missing or wrongly typed key is an Error naming the file and the key (or,
// for an optional one, absent), never undefined behaviour.
#include "workflow/run_summary.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "tests/scratch_dir.h"
#include "workflow/stage_json.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using nlohmann::json;
using testing::ScratchDir;

void WriteJson(const std::string& path, const json& value) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << value.dump(2);
}

json Sidecar() {
  return {{"session", "/s/session.json"},
          {"session_name", "s"},
          {"counts",
           {{"photos", 6},
            {"pixels_examined", 5000000000ull},
            {"accepted", 7000},
            {"rejected", {{"off_sample", 12}, {"grazing_incidence", 0}}}}}};
}

json Consistency() {
  return {{"reciprocity",
           {{"valid", true},
            {"overall_rel_error", 0.02},
            {"per_channel_rel_error", {0.01, 0.02, 0.03}},
            {"bins_compared", 40}}},
          {"isotropy", {{"valid", false}, {"overall_rel_error", nullptr}, {"bins_compared", 0}}}};
}

json Comparison() {
  return {{"overall",
           {{"count", 7000},
            {"median_rel_error", {0.01, 0.02, 0.03}},
            {"p95_rel_error", {0.1, 0.2, 0.3}},
            {"mean_signed_rel_error", {0.0, nullptr, 0.0}}}}};
}

// A run whose one fake stage has written the files of derender, check, compare and reconstruct.
class SummaryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SetVerbosity(0);
    WriteJson(dir_ / "run/samples.npy.json", Sidecar());
    WriteJson(dir_ / "run/consistency.json", Consistency());
    WriteJson(dir_ / "run/truth-comparison.json", Comparison());
    WriteJson(
        dir_ / "run/reconstruction/summary.json",
        {{"table", {{"cells_measured", 10}}},
         {"error_against_truth",
          {{"rel_rms_error", {0.1, 0.1, 0.1}}, {"rel_rms_error_all", 0.1}, {"cells_scored", 99}, {"coverage", 0.5}}}});
  }
  json Build() {
    WorkflowRun run({dir_ / "run", "build", "ibrdf test", false, ""});
    run.Execute({"derender", {"derender"}, {}, {}, "", [] { return 0; }, ""});
    run.Execute({"scan", {}, {}, {}, "no scans", nullptr, ""});
    return BuildRunSummary(run, dir_ / "s", dir_ / "s/truth.json", 1.5);
  }
  ScratchDir dir_;
};

TEST_F(SummaryTest, FieldsFromEveryStage) {
  const json summary = Build();
  EXPECT_EQ(summary["format"], "ibrdf-run");
  EXPECT_EQ(summary["stages"]["derender"]["status"], "ran");
  EXPECT_EQ(summary["stages"]["scan"]["status"], "not_applicable");
  EXPECT_EQ(summary["stages"]["scan"]["reason"], "no scans");
  EXPECT_FALSE(summary["timings_s"].contains("scan"));
  EXPECT_EQ(summary["timings_s"]["this_invocation"], 1.5);
  EXPECT_EQ(summary["session_name"], "s");
  EXPECT_EQ(summary["samples"]["photos"], 6);
  EXPECT_EQ(summary["samples"]["pixels_examined"].get<uint64_t>(), 5000000000ull);  // no int truncation
  EXPECT_EQ(summary["samples"]["rejected"]["off_sample"], 12);
  EXPECT_EQ(summary["consistency"]["reciprocity"], 0.02);
  // A consistency.json of the previous release ("isotropy") is read under the one name.
  EXPECT_TRUE(summary["consistency"]["bilateral_symmetry"].is_null());  // not valid
  EXPECT_EQ(summary["consistency"]["reciprocity_bins_compared"], 40);
  EXPECT_TRUE(summary["consistency"]["bilateral_symmetry_per_channel"].is_null());  // absent: recorded as absent
  EXPECT_EQ(summary["consistency"]["bilateral_symmetry_bins_compared"], 0);
  EXPECT_TRUE(summary["consistency"].contains("isotropy"));  // the old name's copy, for one release
  EXPECT_EQ(summary["reconstruction"]["table"]["cells_measured"], 10);
  EXPECT_TRUE(summary["reconstruction"]["fits"].is_null());
  EXPECT_EQ(summary["truth"]["samples_compared"], 7000);
  EXPECT_TRUE(summary["truth"]["samples_mean_signed_rel_error"][1].is_null());  // a NaN as written
  EXPECT_EQ(summary["truth"]["brdf_cells_scored"], 99);
  EXPECT_FALSE(summary.contains("report"));

  const std::vector<std::string> headline = RunHeadline(summary);
  ASSERT_EQ(headline.size(), 3u);
  EXPECT_EQ(headline[0], "samples: 7000 accepted; rejected: off_sample 12");
  EXPECT_EQ(headline[1], "consistency: reciprocity 2.00 %, bilateral symmetry n/a (medians over bins)");
  EXPECT_EQ(headline[2],
            "against the truth: samples' median relative error (R, G, B) 1.00 %, 2.00 %, 3.00 %; reconstruction "
            "relative RMS 10.00 %, 10.00 %, 10.00 %");
}

// The current consistency.json names the check "bilateral_symmetry" (with an "isotropy" copy): the
// summary and its headline read the one name, and carry the 95th percentile over bins.
TEST_F(SummaryTest, BilateralSymmetryIsReadUnderItsOneName) {
  json consistency = Consistency();
  consistency.erase("isotropy");
  consistency["reciprocity"]["p95_rel_error"] = 0.05;
  consistency["bilateral_symmetry"] = {{"valid", true},
                                       {"overall_rel_error", 0.03},
                                       {"p95_rel_error", 0.07},
                                       {"per_channel_rel_error", {0.03, 0.03, 0.03}},
                                       {"bins_compared", 12}};
  consistency["isotropy"] = {{"valid", true}, {"overall_rel_error", 0.99}, {"bins_compared", 1}};  // ignored
  WriteJson(dir_ / "run/consistency.json", consistency);
  const json summary = Build();
  EXPECT_EQ(summary["consistency"]["bilateral_symmetry"], 0.03);
  EXPECT_EQ(summary["consistency"]["bilateral_symmetry_p95"], 0.07);
  EXPECT_EQ(summary["consistency"]["reciprocity_p95"], 0.05);
  EXPECT_EQ(summary["consistency"]["bilateral_symmetry_bins_compared"], 12);
  EXPECT_EQ(summary["consistency"]["isotropy"], 0.03);  // the copy of the one name, not the file's alias
  EXPECT_EQ(RunHeadline(summary)[1], "consistency: reciprocity 2.00 %, bilateral symmetry 3.00 % (medians over bins)");
}

// Expects Build() to throw an Error naming `file` and `key`.
#define EXPECT_ERROR_NAMING(statement, file, key)                                                         \
  try {                                                                                                   \
    statement;                                                                                            \
    ADD_FAILURE() << "expected an Error naming " << key;                                                  \
  } catch (const Error& e) {                                                                              \
    EXPECT_NE(std::string(e.what()).find(std::string(file) + ": " + key), std::string::npos) << e.what(); \
  }

TEST_F(SummaryTest, MissingRequiredKeyIsAnErrorNamingFileAndKey) {
  json comparison = Comparison();
  comparison["overall"].erase("p95_rel_error");
  WriteJson(dir_ / "run/truth-comparison.json", comparison);
  EXPECT_ERROR_NAMING(Build(), dir_ / "run/truth-comparison.json", "/overall/p95_rel_error: missing");

  WriteJson(dir_ / "run/truth-comparison.json", Comparison());
  json consistency = Consistency();
  consistency["reciprocity"].erase("overall_rel_error");  // valid, so required
  WriteJson(dir_ / "run/consistency.json", consistency);
  EXPECT_ERROR_NAMING(Build(), dir_ / "run/consistency.json", "/reciprocity/overall_rel_error: missing");

  WriteJson(dir_ / "run/consistency.json", Consistency());
  json sidecar = Sidecar();
  sidecar.erase("counts");
  WriteJson(dir_ / "run/samples.npy.json", sidecar);
  EXPECT_ERROR_NAMING(Build(), dir_ / "run/samples.npy.json", "/counts: missing");
}

TEST_F(SummaryTest, WronglyTypedKeyIsAnErrorNamingFileAndKey) {
  json sidecar = Sidecar();
  sidecar["counts"]["accepted"] = "many";
  WriteJson(dir_ / "run/samples.npy.json", sidecar);
  EXPECT_ERROR_NAMING(Build(), dir_ / "run/samples.npy.json", "/counts/accepted: expected a non-negative integer");
}

// A rejection count that is no count is blamed on the sidecar that holds it, not on summary.json.
TEST_F(SummaryTest, WronglyTypedRejectionCountNamesTheSidecar) {
  json sidecar = Sidecar();
  sidecar["counts"]["rejected"]["mixed_pixel"] = "some";
  WriteJson(dir_ / "run/samples.npy.json", sidecar);
  EXPECT_ERROR_NAMING(Build(), dir_ / "run/samples.npy.json",
                      "/counts/rejected/mixed_pixel: expected a non-negative integer");
}

// Optional keys absent take their defaults; files absent leave their section out.
TEST_F(SummaryTest, AbsentOptionalKeysAndFiles) {
  json sidecar = Sidecar();
  sidecar.erase("session_name");
  sidecar["counts"].erase("photos");
  WriteJson(dir_ / "run/samples.npy.json", sidecar);
  fs::remove(dir_ / "run/consistency.json");
  fs::remove(dir_ / "run/truth-comparison.json");
  const json summary = Build();
  EXPECT_EQ(summary["session_name"], "");
  EXPECT_EQ(summary["samples"]["photos"], 0);
  EXPECT_FALSE(summary.contains("consistency"));
  EXPECT_FALSE(summary["truth"].contains("samples_median_rel_error"));
  EXPECT_EQ(summary["truth"]["brdf_coverage"], 0.5);
}

// Derender's exposure advice reaches summary.json and the headline; a sidecar
// without it (older runs) gives an empty list.
TEST_F(SummaryTest, ExposureWarningsReachTheHeadline) {
  EXPECT_TRUE(Build()["samples"]["exposure_warnings"].empty());
  json sidecar = Sidecar();
  sidecar["exposure"] = {{"warnings", json::array({{{"channel", "red"},
                                                    {"cause", "saturated"},
                                                    {"message",
                                                     "exposure: the red channel is clipped; remedy: "
                                                     "take exposure brackets"}}})}};
  WriteJson(dir_ / "run/samples.npy.json", sidecar);
  const json summary = Build();
  ASSERT_EQ(summary["samples"]["exposure_warnings"].size(), 1u);
  const std::vector<std::string> headline = RunHeadline(summary);
  ASSERT_GE(headline.size(), 2u);
  EXPECT_EQ(headline[1], "warning: exposure: the red channel is clipped; remedy: take exposure brackets");
}

TEST(StageJson, TypedAccessByPointer) {
  const StageJson j(json::parse(R"({"a": {"b": [1, 2.5, null]}, "s": "x", "n": -3})"), "f.json");
  EXPECT_TRUE(j.Has("/a/b/1"));
  EXPECT_FALSE(j.Has("/a/b/3"));
  EXPECT_FALSE(j.Has("/a/c"));
  EXPECT_FALSE(j.Has("/s/t"));
  EXPECT_EQ(j.Number("/a/b/1"), 2.5);
  EXPECT_EQ(j.Count("/a/b/0"), 1u);
  EXPECT_EQ(j.Integer("/n"), -3);
  EXPECT_THROW(j.Count("/n"), Error);
  EXPECT_EQ(j.String("/s"), "x");
  EXPECT_EQ(j.String("/t", "fallback"), "fallback");
  EXPECT_THROW(j.String("/a"), Error);
  EXPECT_THROW(j.String("/a", "present, wrong type"), Error);
  EXPECT_EQ(j.Figure("/a/b"), json::parse("[1, 2.5, null]"));
  EXPECT_THROW(j.Figure("/s"), Error);
  EXPECT_EQ(j.ValueOr("/z", 7), 7);
  EXPECT_FALSE(StageJson::ReadIfExists("/nonexistent/file.json").has_value());
}

}  // namespace
}  // namespace ibrdf
