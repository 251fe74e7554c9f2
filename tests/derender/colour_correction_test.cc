// Tests of derender/colour_correction.h: a colour matrix with negative terms takes a dark channel below
// zero; that channel is marked unmeasured (valid 0, brdf and sigma 0) and counted, a sample left with
// no measured channel is removed and counted, and every sample written passes the sample file's
// reader (InvalidSampleReason). Through Derender the counts reach the summary line and the sidecar.
#include "derender/colour_correction.h"

#include <cmath>
#include <limits>
#include <vector>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/brdf_model.h"
#include "derender/derenderer.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

// Unit tilt, theta_i = theta_e = 0: a sample the reader accepts whatever its brdf.
BrdfSample Sample(float r, float g, float b) {
  BrdfSample s{};
  s.wi[2] = s.wo[2] = 1.0f;
  s.brdf[0] = r;
  s.brdf[1] = g;
  s.brdf[2] = b;
  for (float& sigma : s.sigma) sigma = 0.001f;
  s.valid[0] = s.valid[1] = s.valid[2] = 1;
  return s;
}

// One white light and a linear-sRGB chart whose rows sum to 1: the matrix applied is the chart's own.
Session ChartSession(const Eigen::Matrix3d& matrix) {
  Session session;
  session.manifest_path = "session.json";
  session.lights[0].intensity = Eigen::Vector3d::Ones();
  session.photos.resize(1);
  session.colour_chart = ColourChartSpec();
  session.colour_chart->matrix = matrix;
  return session;
}

TEST(ColourCorrection, NegativeChannelIsMarkedUnmeasuredAndCounted) {
  Eigen::Matrix3d m;
  m << 1.5, -0.5, 0.0, 0.0, 1.0, 0.0, 0.0, -0.6, 1.6;
  const Session session = ChartSession(m);
  std::vector<BrdfSample> samples = {
      Sample(0.30f, 0.30f, 0.30f),  // grey: unchanged
      Sample(0.01f, 0.30f, 0.30f),  // red 0.015 - 0.15 < 0: red unmeasured, green and blue kept
      Sample(0.01f, 0.30f, 0.01f),  // red and blue negative, green kept
  };
  ColourCorrectionCounts counts;
  const std::vector<Eigen::Matrix3d> applied = ApplyColourCorrection(session, &samples, &counts);
  ASSERT_EQ(applied.size(), 1u);
  EXPECT_LT((applied[0] - m).norm(), 1e-12);
  ASSERT_EQ(samples.size(), 3u);
  EXPECT_EQ(counts.negative[0], 2u);
  EXPECT_EQ(counts.negative[1], 0u);
  EXPECT_EQ(counts.negative[2], 1u);
  EXPECT_EQ(counts.dropped, 0u);
  EXPECT_TRUE(samples[0].AllValid());
  EXPECT_NEAR(samples[0].brdf[0], 0.30f, 1e-6);
  EXPECT_EQ(samples[1].valid[0], 0);
  EXPECT_EQ(samples[1].brdf[0], 0.0f);
  EXPECT_EQ(samples[1].sigma[0], 0.0f);
  EXPECT_EQ(samples[1].valid[1], 1);
  EXPECT_EQ(samples[1].valid[2], 1);
  EXPECT_EQ(samples[2].valid[0], 0);
  EXPECT_EQ(samples[2].valid[2], 0);
  for (const BrdfSample& s : samples) EXPECT_EQ(InvalidSampleReason(s), "") << InvalidSampleReason(s);
}

// A sample whose every corrected channel is negative or mixes an unmeasured one is removed; a
// channel the matrix makes non-finite is unmeasured too; an already unmeasured channel's value is
// clamped so the file stays readable.
TEST(ColourCorrection, SampleWithNoChannelLeftIsRemovedAndCounted) {
  Eigen::Matrix3d m;
  m << 1.5, -0.5, 0.0, 0.0, 1.0, 0.0, 0.0, -0.6, 1.6;
  const Session session = ChartSession(m);
  BrdfSample green_unmeasured = Sample(0.01f, 0.30f, 0.01f);
  green_unmeasured.valid[1] = 0;  // red and blue mix it: nothing is left
  BrdfSample huge = Sample(std::numeric_limits<float>::max(), 0.0f, 0.30f);  // red overflows to inf
  BrdfSample red_unmeasured = Sample(0.01f, 0.30f, 0.30f);
  red_unmeasured.valid[0] = 0;  // red stays unmeasured, its corrected value (negative) clamped
  std::vector<BrdfSample> samples = {green_unmeasured, huge, red_unmeasured};
  ColourCorrectionCounts counts;
  ApplyColourCorrection(session, &samples, &counts);
  EXPECT_EQ(counts.dropped, 1u);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].valid[0], 0);  // inf
  EXPECT_EQ(samples[0].valid[2], 1);
  EXPECT_EQ(counts.negative[0], 1u);  // the inf; the unmeasured red is not counted again
  EXPECT_EQ(samples[1].valid[0], 0);
  EXPECT_EQ(samples[1].brdf[0], 0.0f);
  for (const BrdfSample& s : samples) EXPECT_EQ(InvalidSampleReason(s), "") << InvalidSampleReason(s);
}

// Through the derenderer: a blue paint under a chart matrix with a strong negative red-from-green term
// (what a fit over a saturated patch can give): red goes negative off the highlight. No
// sample holds a value the reader refuses; the count is in the summary line and the sidecar.
TEST(ColourCorrection, DerenderWritesNoNegativeSampleAndCountsThem) {
  testing::ScratchDir scratch;
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 2;
  options.effects = CameraEffects::None();
  Session session = Session::Load(testing::MakeSession(scratch.str(), options, *material));
  Eigen::Matrix3d m;
  m << 1.0, -0.9, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0;  // diffuse red 0.31 - 0.9 x green 0.40 < 0
  session.colour_chart = ColourChartSpec();
  session.colour_chart->matrix = m;
  const DerenderResult result = Derender(session, DerenderOptions());
  const DerenderSummary& summary = result.summary;
  ASSERT_FALSE(result.samples.empty());
  for (const BrdfSample& s : result.samples) ASSERT_EQ(InvalidSampleReason(s), "") << InvalidSampleReason(s);
  EXPECT_GT(summary.colour_negative[0], 100u);
  EXPECT_EQ(summary.colour_negative[1], 0u);
  EXPECT_GE(summary.channels_not_measured[0], summary.colour_negative[0]);
  EXPECT_EQ(summary.accepted, result.samples.size());
  EXPECT_NE(summary.BriefReport().find("negative after the colour correction"), std::string::npos)
      << summary.BriefReport();
  const nlohmann::json sidecar = DerenderSidecar(session, DerenderOptions(), summary);
  EXPECT_EQ(sidecar["counts"]["colour_negative"][0].get<uint64_t>(), summary.colour_negative[0]);
  ASSERT_TRUE(sidecar["counts"]["rejected"].contains("colour_unmeasured"));
  // The counts add up: every pixel examined is accepted or rejected once.
  uint64_t total = summary.accepted;
  for (const auto& [reason, count] : sidecar["counts"]["rejected"].items()) total += count.get<uint64_t>();
  EXPECT_EQ(total, summary.pixels_examined);
}

}  // namespace
}  // namespace ibrdf
