// Per-channel validity and exposure advice on synthetic sessions: a gold-like paint
// whose blue channel sits under the signal floor wherever its red highlight is absent, and a glossy
// sphere whose single exposure clips the highlight.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_model.h"
#include "core/json_reader.h"
#include "core/sample_file.h"
#include "derender/derenderer.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/reconstruction_error.h"
#include "reconstruct/truth_comparison.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

// The gold-like paint (diffuse albedo 0.06, 0.03, 0.005 under a red-gold GGX highlight) at the default
// noise: the blue channel of many pixels is under the floor while red is well measured. Before per-channel
// validity those pixels were dropped whole (374 k of them), the blue survivors were selected by their
// own noisy value (+1.9 %) and the blue reconstruction came out +6 % to +46 % high at theta_h >= 40
// degrees (docs/decisions.md, "Per-channel validity"). Now: no pixel with a measured channel
// is dropped, the kept blue values are unbiased, and the blue reconstruction is within 2 % in every
// theta_h band.
TEST(ChannelValidity, GoldPaintBlueChannelUnbiased) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("gold-paint"));
  const Session session = Session::Load(MakeSession(dir / "s", SynthOptions(), *material));
  const DerenderResult result = Derender(session, DerenderOptions());
  // The case is exercised: many samples lack blue, none lacks red for the floor, and only pixels with no
  // measured channel are rejected below the floor.
  EXPECT_GT(result.summary.channels_not_measured[2], 200000u);
  EXPECT_LT(result.summary.rejected.at("below_signal"), 1000u);
  EXPECT_GT(result.summary.accepted, 1000000u);

  // The kept blue values: no selection bias (mean signed error per theta band, valid channels only).
  const TruthComparison samples = CompareWithTruth(result.samples, *material);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(samples.overall.bias[c]), 0.005) << "channel " << c;

  // The reconstruction, per theta_h band and channel, in its measured domain.
  const LocalRegression regression(result.samples, LocalRegressionOptions());
  EXPECT_EQ(regression.separate_channels(), 0b101);  // red (clipped highlight pixels) and blue
  const ReconstructionError error = CompareRegressionWithTruth(regression, *material, 80.0, /*stride=*/3);
  int bands = 0;
  for (const ThetaHBandBias& band : error.theta_h_bands) {
    if (band.points < 200) continue;
    ++bands;
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(std::abs(band.mean_rel[c]), 0.02) << "channel " << c << " theta_h " << band.theta_h_min_deg << "-"
                                                  << band.theta_h_max_deg << " deg, " << band.points << " cells";
    }
  }
  EXPECT_GE(bands, 7);

  // The exposure advice names the weak channel and the remedy.
  bool blue_floor = false;
  for (const ExposureWarning& w : result.summary.exposure_warnings) {
    if (w.channel == 2 && w.cause == "below_signal") {
      blue_floor = true;
      EXPECT_GE(w.theta_h_max_deg, 60.0);
      EXPECT_NE(w.message.find("bluer"), std::string::npos) << w.message;
    }
  }
  EXPECT_TRUE(blue_floor);
}

// A small glossy session whose single exposure clips the highlight: derender warns (log, sidecar)
// and names brackets; the same session with a 3-exposure bracket measures the highlight and does not
// warn about clipping.
TEST(ChannelValidity, ClippedSingleExposureWarnsAndNamesBrackets) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("glossy-ggx"));
  SynthOptions options;
  options.rig.num_photos = 6;
  options.rig.width = 320;
  options.rig.height = 240;
  options.rig.exposure_target = 1.0;  // the 99th percentile at the saturation level: the top 1 % clips
  const Session single = Session::Load(MakeSession(dir / "single", options, *material));
  const std::string samples_path = dir / "single.npy";
  const DerenderSummary clipped = DerenderToFile(single, DerenderOptions(), samples_path);
  ASSERT_GT(clipped.channels_not_measured[0] + clipped.rejected.at("saturated"), 0u);
  const nlohmann::json sidecar = ReadJsonFile(SidecarPath(samples_path));
  const nlohmann::json& warnings = sidecar.at("exposure").at("warnings");
  bool named = false;
  for (const nlohmann::json& w : warnings) {
    if (w.at("cause") == "saturated") {
      named = true;
      EXPECT_EQ(w.at("theta_h_deg")[0], 0.0) << w.dump();  // the highlight core
      EXPECT_NE(w.at("message").get<std::string>().find("brackets"), std::string::npos) << w.dump();
    }
  }
  EXPECT_TRUE(named) << sidecar.at("exposure").dump(1);
  // The clipped channels are kept as not measured (valid 0), never as values.
  const std::vector<BrdfSample> samples = ReadSamples(samples_path);
  size_t unmeasured = 0;
  for (const BrdfSample& s : samples) unmeasured += !s.AllValid();
  EXPECT_GT(unmeasured, 0u);

  options.radiometry.brackets = 3;
  const Session bracketed = Session::Load(MakeSession(dir / "bracketed", options, *material));
  const DerenderResult merged = Derender(bracketed, DerenderOptions());
  for (const ExposureWarning& w : merged.summary.exposure_warnings) EXPECT_NE(w.cause, "saturated") << w.message;
  for (const BrdfSample& s : merged.samples) EXPECT_GE(s.exposures, 1);
}

TEST(ExposureAdvice, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ExposureAdviceOptions().Check(&why)) << why;
  ExposureAdviceOptions bad;
  bad.max_below_signal_fraction = 1.5;
  EXPECT_FALSE(bad.Check(&why));
}

// A tally with blue under the floor in bands 40-70 degrees and red clipped in 0-10: one warning each, with
// the range and remedy; a band under the fraction limit gets none.
TEST(ExposureAdvice, WarnsPerChannelRangeWithRemedy) {
  ExposureTally tally;
  const uint8_t ok[3] = {0, 0, 0}, blue_low[3] = {0, 0, 4}, red_clipped[3] = {2, 0, 0};
  for (int b = 0; b < ExposureTally::kBands; ++b) {
    const double theta_h = (b * 10.0 + 5.0) * M_PI / 180.0;
    for (int i = 0; i < 1000; ++i) tally.Add(theta_h, (b >= 4 && b <= 6 && i < 300) ? blue_low : ok);
  }
  for (int i = 0; i < 50; ++i) tally.Add(2.0 * M_PI / 180.0, red_clipped);
  for (int i = 0; i < 40; ++i) tally.Add(85.0 * M_PI / 180.0, blue_low);  // 3.8 % of band 80-90: no warning
  ExposureAdviceOptions options;
  const std::vector<ExposureWarning> warnings = AdviseExposure(tally, options, /*bracketed=*/false);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0].cause, "saturated");
  EXPECT_EQ(warnings[0].channel, 0);
  EXPECT_EQ(warnings[0].theta_h_max_deg, 10.0);
  EXPECT_NE(warnings[0].message.find("brackets"), std::string::npos) << warnings[0].message;
  EXPECT_EQ(warnings[1].cause, "below_signal");
  EXPECT_EQ(warnings[1].channel, 2);
  EXPECT_EQ(warnings[1].theta_h_min_deg, 40.0);
  EXPECT_EQ(warnings[1].theta_h_max_deg, 70.0);
  EXPECT_EQ(warnings[1].pixels_lost, 900u);
  EXPECT_NE(warnings[1].message.find("bluer"), std::string::npos) << warnings[1].message;
  // Already bracketed: the remedy is shorter exposures in the brackets.
  const std::vector<ExposureWarning> again = AdviseExposure(tally, options, /*bracketed=*/true);
  EXPECT_NE(again[0].message.find("shorter exposures"), std::string::npos) << again[0].message;
}

}  // namespace
}  // namespace ibrdf
