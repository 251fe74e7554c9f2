// The analytic derenderer against synthetic sessions with known BRDFs, against the derenderer's accuracy bounds.
#include "derender/derenderer.h"

#include <cstdio>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "reconstruct/truth_comparison.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

SynthOptions NoiseFree(SampleSpec::Kind kind = SampleSpec::Kind::kSphere) {
  SynthOptions options;
  options.scene.sample = kind;
  options.effects = CameraEffects::None();
  return options;
}

// A noise-free session of a Lambertian sphere of albedo 0.5 with `photos` photos.
Session LambertianSession(const ScratchDir& dir, int photos, SynthOptions options = NoiseFree()) {
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  options.rig.num_photos = photos;
  return Session::Load(MakeSession(dir / "s", options, material));
}

TEST(Derender, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(DerenderOptions().Check(&why)) << why;
  DerenderOptions bad;
  bad.pixel_stride = 0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "pixel_stride >= 1 failed: pixel_stride = 0");
}

// A Lambertian sphere must give exactly albedo / pi: every accepted sample within 0.5 %.
TEST(Derender, LambertianSphereGivesAlbedoOverPi) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const Session session = Session::Load(MakeSession(dir / "s", NoiseFree(), material));
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  ASSERT_GT(result.samples.size(), 500000u);
  double worst = 0.0;
  for (const BrdfSample& s : result.samples) {
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(s.brdf[c] * M_PI / 0.5 - 1.0));
  }
  EXPECT_LT(worst, 0.005);
  // Counts add up: every examined pixel is either accepted or rejected for one reason.
  uint64_t rejected = 0;
  for (const auto& [reason, count] : result.summary.rejected) rejected += count;
  EXPECT_EQ(result.summary.accepted + rejected, result.summary.pixels_examined);
  EXPECT_GT(result.summary.rejected.at("off_sample"), 0u);
  EXPECT_GT(result.summary.rejected.at("unlit"), 0u);
}

TEST(Derender, BluepaintSphereNoiseFreeWithinOnePercent) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = Session::Load(MakeSession(dir / "s", NoiseFree(), *material));
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  const TruthComparison comparison = CompareWithTruth(result.samples, *material);
  ASSERT_GT(comparison.overall.count, 500000u);
  for (int c = 0; c < 3; ++c) EXPECT_LT(comparison.overall.median[c], 0.01) << "channel " << c;
}

// With the default camera (12 bits, shot and read noise): median under 5 %, and the per-sample
// uncertainty is calibrated: about 95 % of samples lie within 2 sigma of the truth.
TEST(Derender, BluepaintSphereWithCameraNoise) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  SynthOptions options;
  options.rig.num_photos = 10;
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  ASSERT_TRUE(session.radiometry.noise.has_value());
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  const TruthComparison comparison = CompareWithTruth(result.samples, *material);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(comparison.overall.median[c], 0.05) << "channel " << c;
    EXPECT_GT(comparison.overall.median[c], 0.001) << "noise must show in channel " << c;
    EXPECT_LT(std::abs(comparison.overall.bias[c]), 0.005) << "no scale error in channel " << c;
  }
  size_t within = 0, total = 0;
  for (const BrdfSample& s : result.samples) {
    const Eigen::Vector3d truth = material->Eval(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(),
                                                 Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized());
    for (int c = 0; c < 3; ++c) {
      ASSERT_GT(s.sigma[c], 0.0f);
      within += std::abs(s.brdf[c] - truth[c]) <= 2.0 * s.sigma[c];
      ++total;
    }
  }
  const double fraction = double(within) / total;
  EXPECT_GT(fraction, 0.92);
  EXPECT_LT(fraction, 0.98);
}

// The paper's Figure 4: a cylinder with its axis perpendicular to the plane of camera and light. Every
// sample lies (within the strip's height) in its incidence plane and matches the truth within 1 %.
TEST(Derender, PrimerCylinderSamplesLieInIncidencePlane) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("primer"));
  const SynthOptions options = NoiseFree(SampleSpec::Kind::kCylinder);
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  ASSERT_GT(result.samples.size(), 200000u);
  // Bound from the geometry: the strip's half-height seen from the camera and from the light.
  const double half = 0.5 * options.scene.cylinder_length;
  const double bound = std::atan(half / (options.rig.camera_distance - options.scene.sample_radius)) +
                       std::atan(half / (options.scene.light_distance - options.scene.sample_radius));
  // n . (wi x wo) vanishes for coplanar directions; with n horizontal it is bounded by the sum of the
  // sines of wi's and wo's tilts out of the horizontal plane.
  double worst = 0.0;
  for (const BrdfSample& s : result.samples) {
    const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
    worst = std::max(worst, std::abs(Eigen::Vector3d::UnitZ().dot(wi.cross(wo))));
  }
  EXPECT_LT(worst, bound);
  EXPECT_LT(worst, 0.035);
  const TruthComparison comparison = CompareWithTruth(result.samples, *material);
  for (int c = 0; c < 3; ++c) EXPECT_LT(comparison.overall.median[c], 0.01) << "channel " << c;
}

// A scene 10 km from the origin (scanner coordinates often are) gives the same BRDF values.
TEST(Derender, FarFromOriginGivesSameSamples) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = NoiseFree();
  options.rig.num_photos = 4;
  options.scene.origin = Eigen::Vector3d(1e4, -1e4, 2e3);
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  ASSERT_GT(result.samples.size(), 100000u);
  for (const BrdfSample& s : result.samples) {
    ASSERT_NEAR(s.brdf[0] * M_PI / 0.5, 1.0, 1e-4);
  }
}

// Radiometry: sRGB response, 8 bits and a black level are undone by the session's settings.
TEST(Derender, SrgbEightBitWithBlackLevelIsLinearized) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = NoiseFree();
  options.rig.num_photos = 4;
  options.effects.curve = SensorCurve::kSrgb;
  options.effects.bits = 8;
  options.effects.black_level = 0.02;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  EXPECT_EQ(session.radiometry.response.kind, Response::Kind::kSrgb);
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  const TruthComparison comparison = CompareWithTruth(result.samples, material);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(comparison.overall.median[c], 0.01);
    EXPECT_LT(std::abs(comparison.overall.bias[c]), 0.005);
  }
  // Without the calibration (response taken as linear, no black level) the result is visibly wrong.
  Session wrong = session;
  wrong.radiometry.response.kind = Response::Kind::kLinear;
  wrong.radiometry.black_level = 0.0;
  const TruthComparison uncalibrated = CompareWithTruth(DerenderAnalytic(wrong, DerenderOptions()).samples, material);
  EXPECT_GT(uncalibrated.overall.median[0], 0.2);
}

TEST(Derender, SaturatedPixelsAreRejectedAndCounted) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("glossy-ggx"));
  SynthOptions options = NoiseFree();
  options.rig.num_photos = 4;
  options.rig.exposure_target = 1.0;  // the highlight clips
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  EXPECT_GT(result.summary.rejected.at("saturated"), 0u);
  // A pixel clipped in some channels is kept with those flagged (valid 0, sigma 0); every measured
  // channel is exact (noise-free), so no clipped value is counted as measured.
  size_t flagged = 0;
  for (const BrdfSample& s : result.samples) {
    const Eigen::Vector3d truth = material->Eval(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized(),
                                                 Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized());
    for (int c = 0; c < 3; ++c) {
      if (!s.valid[c]) {
        ++flagged;
        ASSERT_EQ(s.sigma[c], 0.0f);
        continue;
      }
      ASSERT_NEAR(s.brdf[c] / truth[c], 1.0, 1e-3) << "a clipped value slipped through (channel " << c << ")";
    }
  }
  std::printf("%zu channels flagged as clipped\n", flagged);
}

TEST(Derender, StrideAndGrazingLimitsReduceSamples) {
  ScratchDir dir;
  const Session session = LambertianSession(dir, 3);
  const size_t all = DerenderAnalytic(session, DerenderOptions()).samples.size();
  DerenderOptions strided;
  strided.pixel_stride = 2;
  const size_t quarter = DerenderAnalytic(session, strided).samples.size();
  EXPECT_NEAR(double(quarter) / all, 0.25, 0.02);
  DerenderOptions strict;
  strict.max_theta_i_deg = 45.0;
  strict.max_theta_e_deg = 45.0;
  const DerenderResult limited = DerenderAnalytic(session, strict);
  for (const BrdfSample& s : limited.samples) {
    ASSERT_LE(s.theta_i, 45.0 * M_PI / 180.0 + 1e-6);
    ASSERT_LE(s.theta_e, 45.0 * M_PI / 180.0 + 1e-6);
  }
}

TEST(Derender, LightBehindEverySurfaceGivesNoSamples) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 2);
  // Put the light inside the sphere: it is behind every surface point.
  session.lights[0].position = session.sample.center + Eigen::Vector3d(0.001, 0, 0);
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  EXPECT_EQ(result.samples.size(), 0u);
  EXPECT_GT(result.summary.rejected.at("unlit"), 0u);
}

TEST(Derender, CameraInsideSampleIsAnError) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 1);
  session.sample.radius = 2.0;  // swallows the camera
  EXPECT_THROW(DerenderAnalytic(session, DerenderOptions()), Error);
}

TEST(Derender, PhotoWithoutPoseIsAnError) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 1);
  session.photos[0].camera_from_world.reset();
  try {
    DerenderAnalytic(session, DerenderOptions());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/photos/0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ibrdf align"), std::string::npos) << e.what();
  }
}

TEST(Derender, NonFinitePixelsAreRejectedNotPropagated) {
  ScratchDir dir;
  const Session session = LambertianSession(dir, 1);
  // Poison the centre of the photo with NaN.
  Image image = ReadImage(session.PhotoPath(0));
  for (int y = image.height / 2 - 5; y < image.height / 2 + 5; ++y) {
    for (int x = image.width / 2 - 5; x < image.width / 2 + 5; ++x) image.at(x, y, 1) = NAN;
  }
  WriteImage(session.PhotoPath(0), image, PixelFormat::kFloat);
  const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
  // Only green is poisoned: the 100 pixels keep their red and blue, green flagged as not measured
  // (per-channel validity) with a finite value and sigma 0.
  EXPECT_EQ(result.summary.rejected.at("non_finite"), 0u);
  size_t flagged = 0;
  for (const BrdfSample& s : result.samples) {
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(s.brdf[c]) && std::isfinite(s.sigma[c]));
    if (s.valid[1] == 0) {
      ++flagged;
      EXPECT_EQ(s.sigma[1], 0.0f);
      EXPECT_TRUE(s.valid[0] && s.valid[2]);
    }
  }
  EXPECT_EQ(flagged, 100u);
}

TEST(Derender, SidecarHasUnitsCountsAndSession) {
  ScratchDir dir;
  const Session session = LambertianSession(dir, 1);
  const DerenderOptions derender_options;
  const DerenderResult result = DerenderAnalytic(session, derender_options);
  const nlohmann::json sidecar = DerenderSidecar(session, derender_options, result.summary);
  EXPECT_EQ(sidecar["units"]["brdf"], "1/sr");
  EXPECT_EQ(sidecar["counts"]["accepted"].get<uint64_t>(), result.samples.size());
  EXPECT_TRUE(std::filesystem::equivalent(sidecar["session"].get<std::string>(), session.manifest_path));
}

// ---- Real rigs: a light per photo, masks.

// A small noise-free session of `rig` (400 x 300 pixels) with `photos` photos.
Session RigSession(const ScratchDir& dir, SynthRig rig, int photos, const BrdfModel& material) {
  SynthOptions options = NoiseFree();
  options.rig.rig = rig;
  options.rig.num_photos = photos;
  options.rig.width = 400;
  options.rig.height = 300;
  return Session::Load(MakeSession(dir / "s", options, material));
}

// The silent-merge case end to end: a dome's 2 photos share the camera pose but not the light. They
// are two measurements, each derendered with its own light, both matching the truth; derendered as
// if both had one light (the old behaviour's premise) the second photo's samples are far off.
TEST(Derender, DomePhotosOfOnePoseUnderTwoLightsAreTwoMeasurements) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = RigSession(dir, SynthRig::kDome, 2, *material);
  ASSERT_EQ(session.lights.size(), 2u);
  ASSERT_EQ(session.photos[0].camera_from_world->translation, session.photos[1].camera_from_world->translation);
  const DerenderResult result = Derender(session, DerenderOptions());
  EXPECT_EQ(result.summary.photos, 2u);
  std::vector<BrdfSample> per_photo[2];
  for (const BrdfSample& s : result.samples) per_photo[s.image].push_back(s);
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE("photo " + std::to_string(i));
    const TruthComparison comparison = CompareWithTruth(per_photo[i], *material);
    ASSERT_GT(comparison.overall.count, 1000u);
    for (int c = 0; c < 3; ++c) EXPECT_LT(comparison.overall.median[c], 0.01) << "channel " << c;
  }
  // Photo 1 derendered under photo 0's light (what averaging them as one bracket assumed): far off.
  Session wrong = session;
  wrong.photos = {session.photos[1]};
  wrong.photos[0].light = 0;
  const DerenderResult merged = Derender(wrong, DerenderOptions());
  const TruthComparison comparison = CompareWithTruth(merged.samples, *material);
  EXPECT_GT(comparison.overall.median[0], 0.1);
}

// A turntable session: each photo's pose and light are in the sample's frame; the samples match.
TEST(Derender, TurntableSessionMatchesTheTruth) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = RigSession(dir, SynthRig::kTurntable, 3, *material);
  ASSERT_EQ(session.lights.size(), 3u);
  EXPECT_NE(session.lights[0].position, session.lights[1].position);
  const DerenderResult result = Derender(session, DerenderOptions());
  const TruthComparison comparison = CompareWithTruth(result.samples, *material);
  ASSERT_GT(comparison.overall.count, 30000u);
  for (int c = 0; c < 3; ++c) EXPECT_LT(comparison.overall.median[c], 0.01) << "channel " << c;
}

// Masks: the derenderer never samples outside a mask; such pixels on the sample count as "masked";
// a photo's own mask replaces the session's default; counts still add up.
TEST(Derender, MasksExcludePixelsAndAreCounted) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 2);
  const DerenderResult unmasked = Derender(session, DerenderOptions());
  const int w = session.camera.width, h = session.camera.height;
  Image left(w, h, 1), top(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      left.at(x, y, 0) = x < w / 2 ? 1.0f : 0.0f;
      top.at(x, y, 1) = y < h / 2 ? 1.0f : 0.0f;  // any non-zero channel counts
    }
  }
  WriteImage(dir / "s/left.png", left, PixelFormat::kUint8);
  WriteImage(dir / "s/top.png", top, PixelFormat::kUint8);
  session.mask = "left.png";
  session.photos[1].mask = "top.png";
  const DerenderResult masked = Derender(session, DerenderOptions());
  ASSERT_GT(masked.samples.size(), 1000u);
  for (const BrdfSample& s : masked.samples) {
    if (s.image == 0) {
      ASSERT_LT(s.pixel[0], uint32_t(w / 2));
    } else {
      ASSERT_LT(s.pixel[1], uint32_t(h / 2));
    }
  }
  // Exactly the unmasked run's samples inside the masks remain; those outside are counted as masked
  // (with the pixels outside that were rejected for other reasons: the mask is tested first).
  uint64_t inside = 0, outside = 0;
  for (const BrdfSample& s : unmasked.samples) {
    const bool usable = s.image == 0 ? s.pixel[0] < uint32_t(w / 2) : s.pixel[1] < uint32_t(h / 2);
    (usable ? inside : outside) += 1;
  }
  EXPECT_EQ(masked.samples.size(), inside);
  EXPECT_GT(outside, 1000u);
  EXPECT_GE(masked.summary.rejected.at("masked"), outside);
  uint64_t rejected = 0;
  for (const auto& [reason, n] : masked.summary.rejected) rejected += n;
  EXPECT_EQ(masked.summary.accepted + rejected, masked.summary.pixels_examined);
  EXPECT_EQ(masked.summary.rejected.at("off_sample"), unmasked.summary.rejected.at("off_sample"));
}

// Bad input: a mask of the wrong size stops the derender with one error naming the mask and the photo.
TEST(Derender, MaskOfTheWrongSizeNamesBothFiles) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 1);
  WriteImage(dir / "s/small.png", Image(session.camera.width / 2, session.camera.height, 1), PixelFormat::kUint8);
  session.photos[0].mask = "small.png";
  std::string message;
  try {
    Derender(session, DerenderOptions());
  } catch (const Error& error) {
    message = error.what();
  }
  EXPECT_NE(message.find("small.png"), std::string::npos) << message;
  EXPECT_NE(message.find(session.photos[0].file), std::string::npos) << message;
  EXPECT_NE(message.find("mask is"), std::string::npos) << message;
}

// A light without an intensity that no calibration measured is an error naming the photo and the light.
TEST(Derender, LightWithoutIntensityIsAnError) {
  ScratchDir dir;
  Session session = LambertianSession(dir, 1);
  session.lights[0].id = "L05";
  session.lights[0].has_intensity = false;
  std::string message;
  try {
    Derender(session, DerenderOptions());
  } catch (const Error& error) {
    message = error.what();
  }
  EXPECT_NE(message.find("/photos/0"), std::string::npos) << message;
  EXPECT_NE(message.find("light L05, which has no intensity"), std::string::npos) << message;
}

}  // namespace
}  // namespace ibrdf
