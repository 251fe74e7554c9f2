// The alignment's verdicts (align/alignment_verdicts.h) on hand-made results: each check's ok, warn and
// fail against its bound, and EnforceVerdicts (core/verdict.h) stopping on a failure unless it is
// accepted by name, with the measured value, the bound and the remedy in the message.
#include "align/alignment_verdicts.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "tests/error_of.h"

namespace ibrdf {
namespace {

// A sphere session of `photos` measurement photos and one light photo, radius 0.025 m at the origin.
Session Input(int photos) {
  Session session;
  session.manifest_path = "in/session.json";
  session.sample.kind = SampleSpec::Kind::kSphere;
  session.sample.radius = 0.025;
  session.sample.center = Eigen::Vector3d(0.0, 0.0, 0.025);
  for (int i = 0; i < photos; ++i) session.photos.push_back(PhotoSpec());
  PhotoSpec light_photo;
  light_photo.role = PhotoRole::kTargets;
  session.photos.push_back(light_photo);
  return session;
}

// Every photo posed at 0.2 px; the sphere fitted where it was stated.
AlignResult Good(const Session& input) {
  AlignResult result;
  for (size_t i = 0; i < input.photos.size(); ++i) {
    ImageAlignment image;
    image.photo = i;
    image.used = true;
    result.images.push_back(image);
  }
  result.rms_px = 0.2;
  result.sphere.fitted = true;
  result.sphere.radius = input.sample.radius;
  result.sphere.center = input.sample.center;
  return result;
}

const Verdict& Find(const std::vector<Verdict>& verdicts, const std::string& check) {
  for (const Verdict& v : verdicts) {
    if (v.check == check) return v;
  }
  static const Verdict none;
  ADD_FAILURE() << "no verdict " << check;
  return none;
}

TEST(AlignmentVerdicts, AGoodAlignmentIsOkEverywhere) {
  const Session input = Input(6);
  const std::vector<Verdict> verdicts = AlignmentVerdicts(input, Good(input), std::nullopt);
  EXPECT_EQ(verdicts.size(), 5u);  // photos, RMS, radius, centre, limb balance
  EXPECT_EQ(WorstVerdict(verdicts), VerdictLevel::kOk);
  std::vector<Verdict> copy = verdicts;
  EXPECT_NO_THROW(EnforceVerdicts(&copy, AcceptedChecks(), "in/session.json"));
}

// The collapsed sphere of a 2-photo session without a known radius (1.2 um, 0.56 m off the platform):
// two failures, one message naming both with their values, bounds and remedies.
TEST(AlignmentVerdicts, ACollapsedSphereFailsAndStopsUnlessAccepted) {
  const Session input = Input(2);
  AlignResult result = Good(input);
  result.sphere.radius = 1.2e-6;
  result.sphere.center = Eigen::Vector3d(0.5, 0.25, 0.0);
  std::vector<Verdict> verdicts = AlignmentVerdicts(input, result, std::nullopt);
  EXPECT_EQ(Find(verdicts, "sphere.radius").level, VerdictLevel::kFail);
  EXPECT_EQ(Find(verdicts, "sphere.center").level, VerdictLevel::kFail);
  const std::string message = testing::ErrorOf([&] { EnforceVerdicts(&verdicts, AcceptedChecks(), "in/session.json"); });
  EXPECT_NE(message.find("in/session.json"), std::string::npos) << message;
  EXPECT_NE(message.find("sphere.radius: fail: fitted radius 1.2e-06 m"), std::string::npos) << message;
  EXPECT_NE(message.find("radius_known"), std::string::npos) << message;  // the remedy
  EXPECT_NE(message.find("--accept sphere.center"), std::string::npos) << message;
  // Accepting one leaves the other failing; accepting both proceeds and records them.
  AcceptedChecks accept;
  accept.names = {"sphere.radius"};
  EXPECT_THROW(EnforceVerdicts(&verdicts, accept, "in/session.json"), Error);
  accept.names = {"sphere.radius", "sphere.center"};
  EXPECT_NO_THROW(EnforceVerdicts(&verdicts, accept, "in/session.json"));
  EXPECT_TRUE(Find(verdicts, "sphere.radius").accepted);
  const nlohmann::json json = VerdictsToJson(verdicts);
  bool recorded = false;
  for (const nlohmann::json& v : json) recorded |= v["check"] == "sphere.center" && v["accepted"] == true;
  EXPECT_TRUE(recorded) << json.dump();
  accept.names = {"all"};
  EXPECT_NO_THROW(EnforceVerdicts(&verdicts, accept, "in/session.json"));
}

TEST(AlignmentVerdicts, EachBoundSeparatesOkWarnAndFail) {
  const Session input = Input(4);
  auto level = [&](const std::function<void(AlignResult*)>& edit, const std::string& check) {
    AlignResult result = Good(input);
    edit(&result);
    return Find(AlignmentVerdicts(input, result, std::nullopt), check).level;
  };
  EXPECT_EQ(level([](AlignResult* r) { r->images[0].used = false; }, "align.photos_posed"), VerdictLevel::kWarn);
  EXPECT_EQ(level([](AlignResult* r) { r->images[0].used = r->images[1].used = r->images[2].used = false; },
                  "align.photos_posed"),
            VerdictLevel::kFail);
  // The light photo does not count as a measurement photo.
  EXPECT_EQ(level([](AlignResult* r) { r->images[4].used = false; }, "align.photos_posed"), VerdictLevel::kOk);
  EXPECT_EQ(level([](AlignResult* r) { r->rms_px = 0.7; }, "align.reprojection_rms"), VerdictLevel::kWarn);
  EXPECT_EQ(level([](AlignResult* r) { r->rms_px = 1.5; }, "align.reprojection_rms"), VerdictLevel::kFail);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.radius = 0.025 * 1.2; }, "sphere.radius"), VerdictLevel::kOk);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.radius = 0.025 / 1.5; }, "sphere.radius"), VerdictLevel::kWarn);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.radius = 0.025 * 2.5; }, "sphere.radius"), VerdictLevel::kFail);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.center.x() += 0.05; }, "sphere.center"), VerdictLevel::kWarn);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.center.x() += 0.2; }, "sphere.center"), VerdictLevel::kFail);
  EXPECT_EQ(level([](AlignResult* r) { r->sphere.one_sided = true; }, "sphere.limb_balance"), VerdictLevel::kWarn);
  // A known radius is not judged; the centre still is.
  AlignResult known = Good(input);
  known.sphere.radius_fixed = true;
  for (const Verdict& v : AlignmentVerdicts(input, known, std::nullopt)) EXPECT_NE(v.check, "sphere.radius");
  // The light's markers and the mesh registration.
  AlignResult light = Good(input);
  light.light.fitted = true;
  light.light.spread_m = 4e-3;
  EXPECT_EQ(Find(AlignmentVerdicts(input, light, std::nullopt), "light.position").level, VerdictLevel::kWarn);
  light.light.spread_m = 20e-3;
  EXPECT_EQ(Find(AlignmentVerdicts(input, light, std::nullopt), "light.position").level, VerdictLevel::kFail);
  MeshRegistration registration;
  registration.rms_m = 3e-3;
  EXPECT_EQ(Find(AlignmentVerdicts(input, Good(input), registration), "mesh.registration_rms").level,
            VerdictLevel::kFail);
  // A NaN measurement never reads as ok.
  EXPECT_EQ(level([](AlignResult* r) { r->rms_px = std::nan(""); }, "align.reprojection_rms"), VerdictLevel::kFail);
}

}  // namespace
}  // namespace ibrdf
