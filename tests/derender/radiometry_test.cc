// The radiometry must-shows: a session photographed with an sRGB response, a black level,
// vignetting and an unknown light, once calibrated (flat field, white reference), measures the BRDF as
// well as a linear session does and is visibly wrong without calibration; a glossy highlight that
// clips a single exposure is recovered from a bracket of three; bad calibration input is refused.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "calibrate/white_reference_intensity.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "derender/derenderer.h"
#include "radiometry/radiance_image.h"
#include "reconstruct/truth_comparison.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

// Small sessions: 200 x 150 pixels, 4 photos, the default 12-bit camera with shot and read noise.
SynthOptions Small() {
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 4;
  options.scene.light_intensity = Eigen::Vector3d(0.7, 0.9, 1.2);
  return options;
}

TruthComparison Measure(const Session& session, const BrdfModel& truth) {
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  EXPECT_GT(result.summary.accepted, 0u);
  return CompareWithTruth(result.samples, truth);
}

TEST(Radiometry, OptionsAreValid) {
  std::string why;
  EXPECT_TRUE(LightCalibrationOptions().Check(&why)) << why;
  EXPECT_TRUE(SynthRadiometryOptions().Check(&why)) << why;
  LightCalibrationOptions bad;
  bad.interior_fraction = 0.0;
  EXPECT_FALSE(bad.Check(&why));
}

// sRGB, black level, 40 % vignetting and an unknown light: calibrated, the errors match the linear
// session's; uncalibrated (read as linear, no flat field, the stated unit light), they do not.
TEST(Radiometry, CalibratedSrgbSessionMatchesLinearSession) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session linear = Session::Load(MakeSession(dir / "linear", Small(), *material));
  SynthOptions options = Small();
  options.effects.curve = SensorCurve::kSrgb;
  options.effects.black_level = 0.03;
  options.effects.vignetting = 0.4;
  options.radiometry.light_unknown = true;
  const Session session = Session::Load(MakeSession(dir / "srgb", options, *material));
  ASSERT_TRUE(session.calibration && session.calibration->white_reference);
  EXPECT_EQ(session.lights[0].intensity, Eigen::Vector3d::Ones());
  EXPECT_FALSE(session.radiometry.flat_field.empty());

  LightCalibrationReport report;
  const Session calibrated = ApplyLightCalibration(session, &report);
  ASSERT_TRUE(report.success && report.calibrated) << report.BriefReport();
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(calibrated.lights[0].intensity[c] / options.scene.light_intensity[c], 1.0, 0.005)
        << report.BriefReport();
  }

  const TruthComparison reference = Measure(linear, *material);
  const TruthComparison good = Measure(calibrated, *material);
  Session raw = session;  // what a reader that ignores the calibration would do
  raw.radiometry = RadiometrySpec();
  raw.radiometry.noise = session.radiometry.noise;
  raw.calibration.reset();
  raw.lights[0].has_intensity = true;  // taking the placeholder (unit) intensity as stated
  const TruthComparison bad = Measure(raw, *material);
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE("channel " + std::to_string(c) + ": linear " + reference.BriefReport() + "; calibrated " +
                 good.BriefReport() + "; uncalibrated " + bad.BriefReport());
    // Within 1 % (absolute, in relative-error units) of the linear session's median error and bias.
    EXPECT_NEAR(good.overall.median[c], reference.overall.median[c], 0.01);
    EXPECT_NEAR(good.overall.bias[c], reference.overall.bias[c], 0.01);
    EXPECT_GT(good.overall.count, reference.overall.count / 2);
    // Visibly wrong without calibration.
    EXPECT_GT(bad.overall.median[c], 0.2);
  }
  // Each step matters: leaving out any one of them (the white reference calibrated through the same
  // reduced chain) is visibly worse.
  for (int step = 0; step < 4; ++step) {
    Session partial = session;
    const char* names[] = {"response", "black level", "flat field", "white reference"};
    if (step == 0) partial.radiometry.response = Response();
    if (step == 1) partial.radiometry.black_level = 0.0;
    if (step == 2) partial.radiometry.flat_field.clear();
    if (step != 3) partial = ApplyLightCalibration(partial, &report);
    if (step == 3) partial.lights[0].has_intensity = true;  // the unit placeholder, uncalibrated
    const TruthComparison worse = Measure(partial, *material);
    EXPECT_GT(worse.overall.median.maxCoeff(), reference.overall.median.maxCoeff() + 0.02)
        << "without the " << names[step];
  }
}

// A glossy GGX sphere whose highlight clips the auto-exposure: a bracket of three exposures (2 stops
// apart) recovers the highlight's peak within 5 %; the single exposure loses it.
TEST(Radiometry, BracketRecoversClippedHighlight) {
  ScratchDir dir;
  const GgxBrdf material(Eigen::Vector3d(0.25, 0.2, 0.15), Eigen::Vector3d::Constant(0.04), 0.1);
  SynthOptions options = Small();
  options.rig.arc_start_deg = 10.0;
  options.rig.arc_end_deg = 50.0;
  options.radiometry.brackets = 3;
  options.radiometry.bracket_step_ev = 2.0;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.photos.size(), 12u);
  ASSERT_EQ(ExposureGroups(session).size(), 4u);
  Session single = session;  // the auto-exposures alone
  single.photos.clear();
  for (const PhotoSpec& photo : session.photos) {
    if (photo.file.find("-e0.") != std::string::npos) single.photos.push_back(photo);
  }
  ASSERT_EQ(single.photos.size(), 4u);

  const DerenderResult merged = DerenderAnalytic(session, DerenderOptions());
  const DerenderResult one = DerenderAnalytic(single, DerenderOptions());
  auto truth_of = [&](const BrdfSample& s) {
    return material.Eval(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(),
                         Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized());
  };
  double peak = 0.0;
  for (const BrdfSample& s : merged.samples) peak = std::max(peak, truth_of(s).maxCoeff());
  // The mirror configuration's value: the merged samples reach the true peak.
  const double mirror =
      material.Eval(Eigen::Vector3d(0.3, 0, 1).normalized(), Eigen::Vector3d(-0.3, 0, 1).normalized()).maxCoeff();
  EXPECT_GT(peak, 0.9 * mirror);
  // The peak: samples whose truth is at least 80 % of it, measured against the truth.
  Eigen::Vector3d measured_sum = Eigen::Vector3d::Zero(), truth_sum = Eigen::Vector3d::Zero();
  size_t count = 0, within = 0, total = 0;
  for (const BrdfSample& s : merged.samples) {
    const Eigen::Vector3d truth = truth_of(s);
    for (int c = 0; c < 3; ++c) {
      within += std::abs(s.brdf[c] - truth[c]) <= 2.0 * s.sigma[c];
      ++total;
    }
    if (truth.maxCoeff() < 0.8 * peak) continue;
    ++count;
    measured_sum += Eigen::Vector3d(s.brdf[0], s.brdf[1], s.brdf[2]);
    truth_sum += truth;
  }
  ASSERT_GT(count, 20u);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(measured_sum[c] / truth_sum[c], 1.0, 0.05) << "channel " << c;
  // The merged sigma is calibrated: about 95 % of values within 2 sigma of the truth.
  EXPECT_GT(double(within) / total, 0.92);
  EXPECT_LT(double(within) / total, 0.98);
  // The single exposure clips the highlight in green and blue: their measured values stop well short
  // of the peak (the bound per pixel was half the peak; per channel, green's last measured value is
  // 57 %). Red does not clip there; with per-channel validity it is kept and measured, and must read the
  // truth at the highlight.
  EXPECT_GT(one.summary.rejected.at("saturated"), 0u);
  Eigen::Vector3d single_peak = Eigen::Vector3d::Zero(), channel_peak = Eigen::Vector3d::Zero();
  for (const BrdfSample& s : merged.samples) channel_peak = channel_peak.cwiseMax(truth_of(s));
  size_t red_at_peak = 0;
  for (const BrdfSample& s : one.samples) {
    const Eigen::Vector3d truth = truth_of(s);
    for (int c = 0; c < 3; ++c) {
      if (s.valid[c]) single_peak[c] = std::max(single_peak[c], truth[c]);
    }
    if (s.valid[0] && truth[0] > 0.5 * channel_peak[0]) {
      ++red_at_peak;
      EXPECT_NEAR(s.brdf[0] / truth[0], 1.0, 0.05) << "pixel " << s.pixel[0] << " " << s.pixel[1];
    }
  }
  // Green clips first at 57 % of its peak, blue below half of it (measured with this seed).
  EXPECT_LT(single_peak[1], 0.65 * channel_peak[1]);
  EXPECT_LT(single_peak[2], 0.5 * channel_peak[2]);
  EXPECT_GT(red_at_peak, 20u);
  // Clipped pixels of the auto-exposure that the bracket measured.
  EXPECT_LT(merged.summary.rejected.at("saturated"), one.summary.rejected.at("saturated") / 10 + 1);
}

// A white reference that clips is refused with an error naming the photo and saying why.
TEST(Radiometry, SaturatedWhiteReferenceIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = Small();
  options.rig.num_photos = 1;
  options.radiometry.light_unknown = true;
  options.radiometry.white_exposure_scale = 3.0;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  LightCalibrationReport report;
  try {
    ApplyLightCalibration(session, &report);
    FAIL() << "a saturated white reference was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("white-000"), std::string::npos) << message;
    EXPECT_NE(message.find("saturated"), std::string::npos) << message;
  }
  EXPECT_FALSE(report.success);
}

// A white reference that no photo sees (a wrong centre) is refused, naming the manifest's block.
TEST(Radiometry, WhiteReferenceOutOfViewIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = Small();
  options.rig.num_photos = 1;
  options.radiometry.light_unknown = true;
  Session session = Session::Load(MakeSession(dir / "s", options, material));
  session.calibration->white_reference->center += Eigen::Vector3d(0.0, 0.5, 0.0);
  LightCalibrationReport report;
  try {
    ApplyLightCalibration(session, &report);
    FAIL() << "a white reference out of view was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/calibration/white_reference"), std::string::npos) << message;
    EXPECT_NE(message.find("not in view"), std::string::npos) << message;
  }
}

// A flat-field image of the wrong size stops the derender with an error naming the file.
TEST(Radiometry, FlatFieldOfTheWrongSizeIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = Small();
  options.rig.num_photos = 1;
  options.effects.vignetting = 0.3;
  const std::string manifest = MakeSession(dir / "s", options, material);
  WriteImage(dir / "s/flat_field.exr", Image(100, 75, 3), PixelFormat::kFloat);
  const Session session = Session::Load(manifest);
  try {
    DerenderAnalytic(session, DerenderOptions());
    FAIL() << "a mis-sized flat field was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("flat_field.exr"), std::string::npos) << message;
    EXPECT_NE(message.find("100x75"), std::string::npos) << message;
  }
}

// The light and derender stages as `ibrdf run` runs them (`ibrdf lights white`, then `ibrdf derender`:
// DerenderToFile), on a session made as `ibrdf synth --photos 2 --width 200 --height 150 --srgb
// --black-level 0.03 --vignetting 0.4 --light-unknown --light-intensity 0.7 0.9 1.2` makes it: the
// derenderer refuses the uncalibrated session, the light stage calibrates the light and the samples
// match the truth; a saturated white reference stops the light stage with a clear message and no output.
TEST(Radiometry, LightStageCalibratesAndRefusesSaturatedReference) {
  ScratchDir dir;
  const std::string session = dir / "s";
  SynthOptions options;
  options.rig.num_photos = 2;
  options.rig.width = 200;
  options.rig.height = 150;
  options.effects.curve = SensorCurve::kSrgb;
  options.effects.black_level = 0.03;
  options.effects.vignetting = 0.4;
  options.radiometry.light_unknown = true;
  options.scene.light_intensity = Eigen::Vector3d(0.7, 0.9, 1.2);
  const std::string material = MaterialPath("bluepaint");
  ASSERT_TRUE(WriteSyntheticSession(options, *LoadMaterial(material), material, session, false).success);
  std::string refused;
  try {
    DerenderToFile(Session::Load(session), DerenderOptions(), dir / "u.npy");
  } catch (const Error& e) {
    refused = e.what();
  }
  EXPECT_NE(refused.find("/calibration/white_reference"), std::string::npos) << refused;
  EXPECT_NE(refused.find("ibrdf lights white"), std::string::npos) << refused;
  EXPECT_FALSE(std::filesystem::exists(dir / "u.npy"));

  const LightCalibrationReport report =
      WriteLightCalibrationStage(Session::Load(session), LightCalibrationOptions(), dir / "lights", false);
  EXPECT_NE(report.BriefReport().find("light calibration: white reference"), std::string::npos)
      << report.BriefReport();
  const Session calibrated = Session::Load(dir / "lights/session.json");
  EXPECT_FALSE(calibrated.calibration.has_value());
  ASSERT_EQ(calibrated.lights.size(), 1u);
  EXPECT_TRUE(calibrated.lights[0].has_intensity);
  EXPECT_EQ(calibrated.lights[0].intensity, report.lights.at(0).calibrated_intensity);
  const DerenderSummary result = DerenderToFile(calibrated, DerenderOptions(), dir / "a.npy");
  EXPECT_GT(result.accepted, 0u);
  const auto samples = ReadSamples(dir / "a.npy");
  EXPECT_EQ(samples.size(), result.accepted);
  const TruthComparison comparison = CompareWithTruth(samples, *LoadMaterial(MaterialPath("bluepaint")));
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(comparison.overall.bias[c]), 0.01) << "channel " << c;

  Image white = ReadImage(session + "/calibration/white-000.png");
  for (float& v : white.pixels) v = std::min(1.0f, 4.0f * v);
  WriteImage(session + "/calibration/white-000.png", white, PixelFormat::kUint16);
  std::string message;
  try {
    WriteLightCalibrationStage(Session::Load(session), LightCalibrationOptions(), dir / "b", false);
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("white-000.png"), std::string::npos) << message;
  EXPECT_NE(message.find("saturated"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
}

// The session keys round-trip: calibration block, flat field, brackets.
TEST(Radiometry, SessionKeysRoundTrip) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = Small();
  options.rig.num_photos = 2;
  options.effects.vignetting = 0.2;
  options.radiometry.light_unknown = true;
  options.radiometry.brackets = 2;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  session.Save(dir / "s/copy.json");
  const Session copy = Session::Load(dir / "s/copy.json");
  EXPECT_EQ(copy.ToJson(), session.ToJson());
  EXPECT_EQ(copy.radiometry.flat_field, "flat_field.exr");
  ASSERT_EQ(copy.photos.size(), 4u);
  EXPECT_EQ(copy.photos[1].bracket, 0);
  EXPECT_EQ(copy.photos[2].bracket, 1);
  EXPECT_NEAR(copy.photos[1].exposure_s / copy.photos[0].exposure_s, 0.25, 1e-12);
  ASSERT_TRUE(copy.calibration && copy.calibration->white_reference);
  EXPECT_EQ(copy.calibration->white_reference->photos.size(), 1u);
}

// A light per photo (the real-rigs issue): a dome of 3 lights with an unknown intensity each gets a
// white-reference photo per light, and each light's intensity is measured from its own photo (the
// session states none); a light without white-reference photos keeps its stated intensity.
TEST(Radiometry, WhiteReferenceCalibratesEachLightOfADome) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = Small();
  options.rig.rig = SynthRig::kDome;
  options.rig.num_photos = 3;
  options.rig.arc_end_deg = 100.0;  // lights the one target sees well
  options.radiometry.light_unknown = true;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.lights.size(), 3u);
  ASSERT_EQ(session.calibration->white_reference->photos.size(), 3u);
  for (const Light& light : session.lights) EXPECT_FALSE(light.has_intensity);
  LightCalibrationReport report;
  const Session calibrated = ApplyLightCalibration(session, &report);
  ASSERT_EQ(report.lights.size(), 3u) << report.BriefReport();
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(calibrated.lights[k].has_intensity);
    EXPECT_EQ(report.lights[k].light, session.lights[k].id);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(calibrated.lights[k].intensity[c] / options.scene.light_intensity[c], 1.0, 0.005)
          << report.BriefReport();
    }
  }
  const TruthComparison comparison = Measure(calibrated, material);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::abs(comparison.overall.bias[c]), 0.01) << comparison.BriefReport();
  // Only light 1 has a white-reference photo: the others keep what the session states.
  Session partial = session;
  partial.calibration->white_reference->photos = {session.calibration->white_reference->photos[1]};
  partial.lights[0].has_intensity = partial.lights[2].has_intensity = true;
  partial.lights[0].intensity = Eigen::Vector3d(3.0, 3.0, 3.0);
  const Session one = ApplyLightCalibration(partial, &report);
  ASSERT_EQ(report.lights.size(), 1u);
  EXPECT_EQ(one.lights[0].intensity, Eigen::Vector3d(3.0, 3.0, 3.0));
  EXPECT_NEAR(one.lights[1].intensity[0] / options.scene.light_intensity[0], 1.0, 0.005);
}

}  // namespace
}  // namespace ibrdf
