// The align stage against synthetic sessions with markers: poses and the sphere within the required
// bounds, derendering from aligned poses as accurate as from the true ones, and hard or bad input
// answered with a dropped photo or a clear error, never a silent wrong pose.
#include "align/aligner.h"

#include <cmath>
#include <functional>
#include <iostream>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/light_json.h"
#include "derender/derenderer.h"
#include "reconstruct/truth_comparison.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

SynthOptions TargetOptions(int photos) {
  SynthOptions options;
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = photos;
  options.targets.light_photos = 3;  // and 3 photos of the light's markers (role "targets")
  return options;
}

TEST(Align, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(AlignOptions().Check(&why)) << why;
}

// The bounds at the default resolution and camera noise: cameras within 0.5 mm and 0.05
// degrees, the sphere's centre within 0.2 mm and radius within 0.1 mm. Then the derender result of
// the aligned session is as accurate as with the true poses (within a factor 1.5).
TEST(Align, SphereSessionFromItsOwnPhotos) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session truth = Session::Load(MakeSession(dir / "s", TargetOptions(12), *material));
  Session guess = truth;
  guess.sample.center += Eigen::Vector3d(0.002, -0.001, 0.0015);  // a rough start: 2.7 mm off
  guess.sample.radius *= 1.03;
  const AlignResult result = AlignSession(guess, AlignOptions());
  ASSERT_EQ(result.session.photos.size(), truth.photos.size());
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    const Rigid3d& estimated = *result.session.photos[i].camera_from_world;
    const Rigid3d& expected = *truth.photos[i].camera_from_world;
    EXPECT_LT((estimated.Inverse().translation - expected.Inverse().translation).norm(), 0.5e-3) << "photo " << i;
    EXPECT_LT(estimated.rotation.angularDistance(expected.rotation) * 180.0 / M_PI, 0.05) << "photo " << i;
  }
  ASSERT_TRUE(result.sphere.fitted);
  EXPECT_LT((result.sphere.center - truth.sample.center).norm(), 0.2e-3);
  EXPECT_NEAR(result.sphere.radius, truth.sample.radius, 0.1e-3);

  const TruthComparison with_truth = CompareWithTruth(DerenderAnalytic(truth, DerenderOptions()).samples, *material);
  const DerenderResult aligned_samples = DerenderAnalytic(result.session, DerenderOptions());
  const TruthComparison with_aligned = CompareWithTruth(aligned_samples.samples, *material);
  // Alignment-only photos are skipped and not counted: the counts still add up.
  uint64_t rejected = 0;
  for (const auto& [reason, count] : aligned_samples.summary.rejected) rejected += count;
  EXPECT_EQ(aligned_samples.summary.accepted + rejected, aligned_samples.summary.pixels_examined);
  EXPECT_LT(aligned_samples.summary.photos, result.session.photos.size());
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(with_aligned.overall.median[c], 1.5 * with_truth.overall.median[c]) << "channel " << c;
  }
}

// Photos that see too few reference markers are dropped with a reason, not posed from too little.
TEST(Align, PhotoWithTooFewMarkersIsDroppedWithAReason) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  Session session = Session::Load(MakeSession(dir / "s", TargetOptions(2), material));
  session.targets->reference.resize(1);  // only marker 0 is reference: at most one per photo
  AlignOptions options;
  options.fit_sphere = false;
  EXPECT_THROW(AlignSession(session, options), Error);  // nothing can be posed: a clear refusal
  session = Session::Load(dir / "s");
  session.targets->reference.resize(3);
  options.min_markers_per_image = 3;
  try {
    const AlignResult result = AlignSession(session, options);
    for (const ImageAlignment& image : result.images) {
      if (!image.used) {
        EXPECT_TRUE(image.dropped_reason.find("markers seen") != std::string::npos ||
                    image.dropped_reason.find("poorly determined") != std::string::npos)
            << image.dropped_reason;
      }
    }
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no photo could be aligned"), std::string::npos) << e.what();
  }
}

TEST(Align, MarkerIdListedTwiceIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = TargetOptions(1);
  options.rig.width = 160;
  options.rig.height = 120;
  Session session = Session::Load(MakeSession(dir / "s", options, material));
  session.targets->reference[1].id = session.targets->reference[0].id;
  session.Save(dir / "s/session.json");
  try {
    Session::Load(dir / "s");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/targets/reference/1/id"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("listed twice"), std::string::npos) << e.what();
  }
}

// The bound for the light: within 1 mm of the truth at the default noise, from the markers on
// its card seen in the target photos (whose poses come from the platform's ring). Target photos are
// posed, kept in the aligned session and marked.
TEST(Align, LightFromItsMarkers) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const Session truth = Session::Load(MakeSession(dir / "s", TargetOptions(4), material));
  ASSERT_TRUE(truth.targets && truth.targets->light);
  int target_photos = 0;
  for (const PhotoSpec& photo : truth.photos) target_photos += photo.role == PhotoRole::kTargets;
  EXPECT_EQ(target_photos, 3);
  Session guess = truth;
  guess.lights[0].position += Eigen::Vector3d(0.05, -0.03, 0.02);
  AlignOptions options;
  options.fit_sphere = false;
  const AlignResult result = AlignSession(guess, options);
  ASSERT_TRUE(result.light.fitted) << result.light.reason;
  for (const LightMarkerFit& marker : result.light.markers) {
    EXPECT_GE(marker.photos, 2) << "marker " << marker.id;
    EXPECT_LT(marker.rms_px, 0.2) << "marker " << marker.id;
  }
  const double error = (result.light.position - truth.lights[0].position).norm();
  std::cout << "light error " << 1e3 * error << " mm, spread " << 1e3 * result.light.spread_m << " mm\n";
  EXPECT_LT(error, 1e-3);
  EXPECT_LT((result.session.lights[0].position - truth.lights[0].position).norm(), 1e-3);
  ASSERT_EQ(result.session.photos.size(), truth.photos.size());
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    EXPECT_EQ(result.session.photos[i].role, truth.photos[i].role) << "photo " << i;
    const Rigid3d& estimated = *result.session.photos[i].camera_from_world;
    const Rigid3d& expected = *truth.photos[i].camera_from_world;
    EXPECT_LT((estimated.Inverse().translation - expected.Inverse().translation).norm(), 0.5e-3) << "photo " << i;
    EXPECT_LT(estimated.rotation.angularDistance(expected.rotation) * 180.0 / M_PI, 0.05) << "photo " << i;
  }
}

// A two-photo session on the marker platform without its target photos: nothing sees the light's card.
Session WithoutTargetPhotos(const std::string& dir) {
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  Session session = Session::Load(MakeSession(dir, TargetOptions(2), material));
  std::vector<PhotoSpec> measurement;
  for (const PhotoSpec& photo : session.photos) {
    if (photo.role == PhotoRole::kMeasurement) measurement.push_back(photo);
  }
  session.photos = measurement;
  return session;
}

// Without target photos nothing sees the light's card: the light stays as given, and the result says
// why (never a guess).
TEST(Align, LightUnseenStaysAsGivenWithAReason) {
  ScratchDir dir;
  Session session = WithoutTargetPhotos(dir / "s");
  AlignOptions options;
  options.fit_sphere = false;
  const AlignResult result = AlignSession(session, options);
  EXPECT_FALSE(result.light.fitted);
  EXPECT_NE(result.light.reason.find("no marker of the light"), std::string::npos) << result.light.reason;
  EXPECT_EQ(result.session.lights[0].position, session.lights[0].position);
}

// A light the session could not place ("position": "unknown", as session init writes it for a light
// with markers) and whose markers no photo sees: align stops with what it measured and the remedy,
// rather than keep the placeholder.
TEST(Align, UnknownLightUnseenIsAVerdictNotAPlaceholder) {
  ScratchDir dir;
  Session session = WithoutTargetPhotos(dir / "s");
  session.lights[0].placement_known = false;
  AlignOptions options;
  options.fit_sphere = false;
  try {
    AlignSession(session, options);
    ADD_FAILURE() << "align kept an unknown light";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("light fit failed"), std::string::npos) << message;
    EXPECT_NE(message.find("0 of 0 light photos posed"), std::string::npos) << message;
    EXPECT_NE(message.find("--light-position-m"), std::string::npos) << message;
  }
}

// With its light photos, the same unknown light is found and the aligned session states it.
TEST(Align, UnknownLightIsFoundFromItsMarkers) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  Session session = Session::Load(MakeSession(dir / "s", TargetOptions(2), material));
  const Eigen::Vector3d truth = session.lights[0].position;
  session.lights[0].placement_known = false;
  session.lights[0].position = Eigen::Vector3d::Zero();
  AlignOptions options;
  options.fit_sphere = false;
  // The session format writes the unknown position as "unknown" (the one light writer).
  EXPECT_EQ(LightJson(session.lights[0]).at("position"), "unknown");
  const AlignResult result = AlignSession(session, options);
  ASSERT_TRUE(result.light.fitted) << result.light.reason;
  EXPECT_TRUE(result.session.lights[0].placement_known);
  EXPECT_LT((result.session.lights[0].position - truth).norm(), 5e-3);
}

// The light block and photo roles round-trip; an unknown key in the light block, an id on both the
// light and the reference layout, and an unknown role are errors naming the field.
TEST(Align, LightTargetsAndPhotoRolesInTheSessionFile) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = TargetOptions(1);
  options.rig.width = 160;
  options.rig.height = 120;
  options.targets.light_photos = 1;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_TRUE(session.targets->light);
  EXPECT_EQ(session.targets->light->markers.size(), 2u);
  EXPECT_EQ(session.photos.back().role, PhotoRole::kTargets);
  EXPECT_EQ(session.photos.front().role, PhotoRole::kMeasurement);
  const nlohmann::json json = session.ToJson();
  EXPECT_EQ(json["photos"].back()["role"], "targets");
  EXPECT_FALSE(json["photos"].front().contains("role"));

  auto expect_error = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& where,
                          const std::string& what) {
    nlohmann::json broken = json;
    edit(broken);
    WriteJsonFile(dir / "s/session.json", broken);
    try {
      Session::Load(dir / "s");
      ADD_FAILURE() << "expected an error at " << where;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error([](nlohmann::json& j) { j["targets"]["light"]["sise"] = 0.06; }, "/targets/light/sise", "unknown key");
  expect_error([](nlohmann::json& j) { j["targets"]["light"]["markers"][1]["id"] = 3; }, "/targets/light/markers/1/id",
               "listed twice");
  expect_error([](nlohmann::json& j) { j["targets"]["light"]["markers"][1]["id"] = 20; }, "/targets/light/markers/1/id",
               "listed twice");
  expect_error([](nlohmann::json& j) { j["targets"]["light"]["markers"] = nlohmann::json::array(); },
               "/targets/light/markers", "at least one");
  expect_error([](nlohmann::json& j) { j["photos"][0]["role"] = "calibration"; }, "/photos/0/role", "unknown role");
  WriteJsonFile(dir / "s/session.json", json);
  const Session reloaded = Session::Load(dir / "s");
  EXPECT_EQ(reloaded.ToJson()["targets"], json["targets"]);
  EXPECT_EQ(reloaded.photos.back().role, PhotoRole::kTargets);
}

TEST(Align, SessionWithoutTargetsIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.num_photos = 1;
  options.rig.width = 64;
  options.rig.height = 48;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  try {
    AlignSession(session, AlignOptions());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/targets"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
