// The white reference posed by its card's markers: `ibrdf synth --white-card`
// renders the card of `ibrdf targets` (a white patch framed by 4 markers) where the sample was, seen
// with the platform; with its pose and the light's intensity dropped from session.json (nothing typed),
// the align stage poses the card and the light calibration must then measure the light's intensity
// within 0.5 % of the truth.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "align/aligner.h"
#include "align/targets.h"
#include "align/white_reference_pose.h"
#include "calibrate/white_reference_intensity.h"
#include "core/error.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;

// The capture a lab leaves: the platform, a few measurement photos, the card in its own photo.
SynthOptions CardOptions() {
  SynthOptions options;
  options.targets.enabled = true;
  options.targets.white_card = true;
  options.radiometry.light_unknown = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = 3;
  options.scene.light_intensity = Eigen::Vector3d(2.3, 1.7, 0.9);
  return options;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

void WriteJson(const std::string& path, const nlohmann::json& json) { std::ofstream(path) << json.dump(2); }

class WhiteCard : public ::testing::Test {
 protected:
  // One session for the suite (ScratchDir needs a running test, so the folder is made here): the
  // synthetic truth, then the manifest as a user writes it: no white-reference pose, no photo poses.
  static void SetUpTestSuite() {
    dir_ = new std::string(
        (std::filesystem::temp_directory_path() / ("ibrdf-WhiteCard-" + std::to_string(::getpid()))).string());
    std::filesystem::create_directories(*dir_);
    const LambertianBrdf material(Eigen::Vector3d(0.6, 0.5, 0.4));
    const std::string manifest = MakeSession(*dir_ + "/s", CardOptions(), material);
    truth_ = new Session(Session::Load(manifest));
    nlohmann::json json = ReadJson(manifest);
    nlohmann::json& white = json["calibration"]["white_reference"];
    white.erase("center");
    white.erase("normal");
    for (nlohmann::json& photo : white["photos"]) photo.erase("camera_from_world");
    for (nlohmann::json& photo : json["photos"]) photo.erase("camera_from_world");
    WriteJson(manifest, json);
    untyped_ = new Session(Session::Load(manifest));
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete untyped_;
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static std::string* dir_;
  static Session* truth_;
  static Session* untyped_;
};
std::string* WhiteCard::dir_ = nullptr;
Session* WhiteCard::truth_ = nullptr;
Session* WhiteCard::untyped_ = nullptr;

// The card's layout is the printed one: synth's targets block equals `ibrdf targets`' for the card.
TEST_F(WhiteCard, SynthUsesThePrintedLayout) {
  ASSERT_TRUE(truth_->targets && truth_->targets->white_reference);
  TargetSheetsOptions sheets;
  const TargetsSpec printed = TargetLayout(sheets);
  ASSERT_TRUE(printed.white_reference);
  ASSERT_EQ(printed.white_reference->markers.size(), truth_->targets->white_reference->markers.size());
  for (size_t m = 0; m < printed.white_reference->markers.size(); ++m) {
    EXPECT_EQ(printed.white_reference->markers[m].id, truth_->targets->white_reference->markers[m].id);
    for (int k = 0; k < 4; ++k) {
      EXPECT_LT(
          (printed.white_reference->markers[m].corners[k] - truth_->targets->white_reference->markers[m].corners[k])
              .norm(),
          1e-12);
    }
  }
}

// Nothing typed: the manifest has no pose, and derender's light calibration refuses it, naming align.
TEST_F(WhiteCard, UnposedWhiteReferenceIsRefusedByTheLightCalibration) {
  ASSERT_TRUE(untyped_->calibration && untyped_->calibration->white_reference);
  EXPECT_FALSE(untyped_->calibration->white_reference->posed);
  EXPECT_FALSE(untyped_->lights[0].has_intensity);
  for (const PhotoSpec& photo : untyped_->calibration->white_reference->photos) EXPECT_FALSE(photo.camera_from_world);
  // The saved manifest keeps it unposed (no centre or normal written).
  const nlohmann::json json = untyped_->ToJson();
  EXPECT_FALSE(json["calibration"]["white_reference"].contains("center"));
  LightCalibrationReport report;
  try {
    ApplyLightCalibration(*untyped_, &report);
    FAIL() << "an unposed white reference was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/calibration/white_reference"), std::string::npos) << message;
    EXPECT_NE(message.find("ibrdf align"), std::string::npos) << message;
  }
}

// The must-show figure: align poses the card, the light calibration measures the intensity within 0.5 %.
TEST_F(WhiteCard, AlignPosesTheCardAndTheLightIsWithinHalfAPercent) {
  const AlignResult aligned = AlignSession(*untyped_, AlignOptions());
  ASSERT_TRUE(aligned.white_reference.posed) << aligned.BriefReport();
  const WhiteReferenceSpec& truth = *truth_->calibration->white_reference;
  const WhiteReferenceSpec& white = *aligned.session.calibration->white_reference;
  EXPECT_TRUE(white.posed);
  ASSERT_EQ(white.photos.size(), truth.photos.size());
  for (const PhotoSpec& photo : white.photos) ASSERT_TRUE(photo.camera_from_world);
  const double center_error = (white.center - truth.center).norm();
  const double normal_error_deg = std::acos(std::min(1.0, white.normal.dot(truth.normal))) * 180.0 / M_PI;
  RecordProperty("center_error_mm", std::to_string(1e3 * center_error));
  RecordProperty("normal_error_deg", std::to_string(normal_error_deg));
  std::cout << aligned.white_reference.BriefReport() << "\ncentre error " << 1e3 * center_error << " mm, normal error "
            << normal_error_deg << " deg\n";
  EXPECT_LT(center_error, 1e-3);
  EXPECT_LT(normal_error_deg, 0.2);
  // The predicted uncertainty is finite, positive and not wildly off the actual error.
  const double sigma = std::sqrt(aligned.white_reference.center_covariance.trace());
  EXPECT_GT(sigma, 0.0);
  EXPECT_LT(center_error, 10.0 * sigma + 1e-4);
  EXPECT_GT(aligned.white_reference.intensity_sigma_relative.at(0), 0.0);
  EXPECT_LT(aligned.white_reference.intensity_sigma_relative.at(0), 0.005);
  const nlohmann::json json = ToJson(aligned);
  ASSERT_TRUE(json.contains("white_reference"));
  EXPECT_EQ(json["white_reference"]["posed_by"], "markers");
  EXPECT_TRUE(json["white_reference"].contains("center_covariance_m2"));

  LightCalibrationReport report;
  const Session calibrated = ApplyLightCalibration(aligned.session, &report);
  ASSERT_TRUE(report.calibrated) << report.BriefReport();
  const Eigen::Vector3d expected = CardOptions().scene.light_intensity;
  std::cout << report.BriefReport() << "\n";
  for (int c = 0; c < 3; ++c) {
    const double relative = calibrated.lights[0].intensity[c] / expected[c] - 1.0;
    RecordProperty("intensity_error_" + std::to_string(c), std::to_string(relative));
    std::cout << "channel " << c << ": intensity error " << 100.0 * relative << " %\n";
    EXPECT_LT(std::abs(relative), 0.005) << "channel " << c;
  }
}

// A card whose markers are not in the photos (wrong ids in the targets block) is an error naming the
// white reference, not a silent fallback.
TEST_F(WhiteCard, CardMarkersNotSeenIsAnError) {
  Session session = *untyped_;
  for (TargetSpec& marker : session.targets->white_reference->markers) marker.id += 4;
  try {
    AlignSession(session, AlignOptions());
    FAIL() << "a white reference without visible markers was posed";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/calibration/white_reference"), std::string::npos) << message;
    EXPECT_NE(message.find("cannot be posed"), std::string::npos) << message;
  }
}

// Leaving the pose out needs the card's markers: without them the manifest is refused at load.
TEST_F(WhiteCard, PoseLeftOutWithoutCardMarkersIsAnError) {
  const std::string manifest = *dir_ + "/s/session.json";
  nlohmann::json json = ReadJson(manifest);
  json["targets"].erase("white_reference");
  const std::string copy = *dir_ + "/s/no-card.json";
  WriteJson(copy, json);
  try {
    Session::Load(copy);
    FAIL() << "a white reference without pose or card markers was accepted";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("/calibration/white_reference/center"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace ibrdf
