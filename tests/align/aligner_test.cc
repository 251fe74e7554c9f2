// The align stage against synthetic sessions with markers: poses and the sphere within the issue's
// bounds, derendering from aligned poses as accurate as from the true ones, and hard or bad input
// answered with a dropped photo or a clear error, never a silent wrong pose.
#include "align/aligner.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
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
  options.targets = true;
  options.camera_elevation_deg = 45.0;
  options.num_photos = photos;
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
  ASSERT_TRUE(result.success);
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
  const TruthComparison with_aligned =
      CompareWithTruth(DerenderAnalytic(result.session, DerenderOptions()).samples, *material);
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
        EXPECT_NE(image.dropped_reason.find("reference markers"), std::string::npos);
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
  options.width = 160;
  options.height = 120;
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

TEST(Align, SessionWithoutTargetsIsAnError) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.num_photos = 1;
  options.width = 64;
  options.height = 48;
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
