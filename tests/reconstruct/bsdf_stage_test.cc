// The reconstruct stage writes NAME.bsdf: the RGL file read back as the readers do matches ibrdf's table
// over the measured domain, names what it invented, and serves as a truth for the samples.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/rgl_bsdf.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/truth_comparison.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::ScratchDir;
using testing::SessionSamples;

TEST(BsdfStage, ReconstructWritesABsdfThatMatchesTheTable) {
  const auto truth = LoadMaterial(MaterialPath("bluepaint"));
  const std::vector<BrdfSample> samples = SessionSamples(*truth, CameraEffects::None(), 10, 200, 150);
  ScratchDir dir;  // after SessionSamples, whose scratch folder has the same name
  ReconstructOptions options;
  options.name = "paint";
  const ReconstructResult result = Reconstruct(samples, options, dir / "rec", "samples.npy");
  ASSERT_TRUE(result.success);
  ASSERT_TRUE(result.bsdf_written);
  const std::string path = dir / "rec/paint.bsdf";
  ASSERT_TRUE(std::filesystem::exists(path));
  const nlohmann::json& bsdf = result.summary["bsdf"];
  std::printf("bsdf against the table (measured cells): median %.3f %%, p95 %.3f %%\n", 100 * result.bsdf_median_error,
              100 * result.bsdf_p95_error);
  // The stated error of the file against the table over its measured cells (theta <= 80 degrees).
  EXPECT_GT(bsdf["error_against_table"]["values"].get<size_t>(), 10000u);
  EXPECT_LT(result.bsdf_median_error, 0.01);
  EXPECT_LT(result.bsdf_p95_error, 0.06);
  // The description names ibrdf and says what is unmeasured and how it was filled.
  const RglBsdf file(path);
  EXPECT_NE(file.description().find("ibrdf reconstruct"), std::string::npos);
  EXPECT_NE(file.description().find("unmeasured"), std::string::npos);
  if (bsdf["nodes"]["unmeasured"].get<uint64_t>() > 0) {
    EXPECT_NE(file.description().find("fit (invented values)"), std::string::npos) << file.description();
  }
  // As a truth: the samples against the file are as close as against the true BRDF (within 1.5x).
  const TruthComparison against_file = CompareWithTruth(samples, *LoadTruthFile(path));
  const TruthComparison against_truth = CompareWithTruth(samples, *truth);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(against_file.overall.median[c], 1.5 * against_truth.overall.median[c] + 0.002) << c;
  }
}

TEST(BsdfStage, NoBsdfSkipsIt) {
  const auto truth = LoadMaterial(MaterialPath("bluepaint"));
  const std::vector<BrdfSample> samples = SessionSamples(*truth, CameraEffects::None(), 6, 120, 90);
  ScratchDir dir;
  ReconstructOptions options;
  options.name = "paint";
  options.fits = false;
  options.bsdf = false;
  const ReconstructResult result = Reconstruct(samples, options, dir / "rec", "samples.npy");
  ASSERT_TRUE(result.success);
  EXPECT_FALSE(result.bsdf_written);
  EXPECT_FALSE(std::filesystem::exists(dir / "rec/paint.bsdf"));
  EXPECT_FALSE(result.summary.contains("bsdf"));
}

}  // namespace
}  // namespace ibrdf
