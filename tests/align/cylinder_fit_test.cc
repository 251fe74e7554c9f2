// The cylinder's pose from the markers on its top cap: a synthetic cylinder session with a
// ring of reference markers and three small markers on the cap. The cameras within the bounds,
// the axis and centre from the markers' bundle-adjusted corners, and derendering the aligned session
// as accurate as with the true pose (within a factor 1.5).
#include "align/cylinder_fit.h"

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "align/aligner.h"
#include "align/alignment_verdicts.h"
#include "core/math.h"
#include "derender/derenderer.h"
#include "reconstruct/truth_comparison.h"
#include "synth/synthetic_targets.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

TEST(CylinderFit, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(CylinderFitOptions().Check(&why)) << why;
}

// Exact corners: the fit recovers a tilted, shifted cylinder exactly; one marker moved 5 mm is left
// out; a single marker is too little (a clear reason, the sample stays as given).
TEST(CylinderFit, RigidFitOfExactCornersAndOutliers) {
  SynthOptions options;
  options.targets.enabled = true;
  options.scene.sample = SampleSpec::Kind::kCylinder;
  options.targets.sample_marker_count = 4;
  const SampleTargetsSpec spec = SampleTargetLayout(options, nullptr);
  ASSERT_EQ(spec.markers.size(), 4u);
  const Rigid3d world_from_sample(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 0).normalized())),
                                  Eigen::Vector3d(0.01, -0.02, 0.005));
  std::map<int, BundleMarker> markers;
  for (const TargetSpec& target : spec.markers) {
    BundleMarker& marker = markers[target.id];
    marker.id = target.id;
    marker.posed = true;
    marker.fixed = true;
    marker.images = 3;
    for (int c = 0; c < 4; ++c) marker.corners[c] = world_from_sample * target.corners[c];
  }
  SampleSpec given;
  given.kind = SampleSpec::Kind::kCylinder;
  CylinderFit fit = FitCylinderToMarkers(spec, markers, given, CylinderFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.center - world_from_sample.translation).norm(), 1e-9);
  EXPECT_LT(std::acos(std::min(1.0, fit.axis.dot(world_from_sample.rotation * Eigen::Vector3d::UnitZ()))), 1e-8);

  for (Eigen::Vector3d& c : markers.at(spec.markers[1].id).corners) c += Eigen::Vector3d(0.005, 0.0, 0.0);
  fit = FitCylinderToMarkers(spec, markers, given, CylinderFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_EQ(fit.rejected_markers, 1);
  EXPECT_LT((fit.center - world_from_sample.translation).norm(), 1e-8);

  for (size_t m = 1; m < spec.markers.size(); ++m) markers.at(spec.markers[m].id).posed = false;
  fit = FitCylinderToMarkers(spec, markers, given, CylinderFitOptions());
  EXPECT_FALSE(fit.fitted);
  EXPECT_NE(fit.reason.find("only 1"), std::string::npos) << fit.reason;
}

TEST(CylinderFit, CylinderSessionFromItsOwnPhotos) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  SynthOptions options;
  options.scene.sample = SampleSpec::Kind::kCylinder;
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = 6;
  const Session truth = Session::Load(MakeSession(dir / "s", options, *material));
  ASSERT_TRUE(truth.targets->sample);
  Session guess = truth;
  guess.sample.center += Eigen::Vector3d(0.003, -0.002, 0.001);
  guess.sample.axis = Eigen::Vector3d(0.05, 0.03, 1.0).normalized();
  const AlignResult result = AlignSession(guess, AlignOptions());
  std::cout << result.bundle.BriefReport() << "\n" << result.BriefReport() << "\n";
  ASSERT_EQ(result.session.photos.size(), truth.photos.size());
  double worst_position = 0.0, worst_rotation = 0.0;
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    const Rigid3d& estimated = *result.session.photos[i].camera_from_world;
    const Rigid3d& expected = *truth.photos[i].camera_from_world;
    const double position = (estimated.Inverse().translation - expected.Inverse().translation).norm();
    const double rotation = estimated.rotation.angularDistance(expected.rotation) / kDegree;
    worst_position = std::max(worst_position, position);
    worst_rotation = std::max(worst_rotation, rotation);
    EXPECT_LT(position, 0.5e-3) << "photo " << i;
    EXPECT_LT(rotation, 0.05) << "photo " << i;
  }
  ASSERT_TRUE(result.cylinder.fitted) << result.cylinder.reason;
  EXPECT_EQ(result.cylinder.markers, 3);
  const double centre_error = (result.session.sample.center - truth.sample.center).norm();
  const double axis_error_deg = std::acos(std::min(1.0, result.session.sample.axis.dot(truth.sample.axis))) / kDegree;
  EXPECT_LT(centre_error, 0.2e-3);
  EXPECT_LT(axis_error_deg, 0.2);
  // The fit's verdicts: placed, corners within 0.5 mm. With the cylinder's markers out of every view
  // the fit fails, and so does its verdict: the guessed pose is never used silently.
  const auto verdict_of = [](const std::vector<Verdict>& verdicts, const std::string& check) {
    for (const Verdict& v : verdicts) {
      if (v.check == check) return v.level;
    }
    return VerdictLevel::kOk;
  };
  const std::vector<Verdict> verdicts = AlignmentVerdicts(guess, result, std::nullopt);
  EXPECT_EQ(verdict_of(verdicts, "cylinder.marker_rms"), VerdictLevel::kOk);
  EXPECT_EQ(verdict_of(verdicts, "cylinder.fitted"), VerdictLevel::kOk);
  AlignResult unplaced = result;
  unplaced.cylinder = CylinderFit();
  unplaced.cylinder.reason = "only 1 of the sample's markers posed (need 2)";
  EXPECT_EQ(verdict_of(AlignmentVerdicts(guess, unplaced, std::nullopt), "cylinder.fitted"), VerdictLevel::kFail);
  AlignResult loose = result;
  loose.cylinder.rms_m = 3e-3;
  EXPECT_EQ(verdict_of(AlignmentVerdicts(guess, loose, std::nullopt), "cylinder.marker_rms"), VerdictLevel::kFail);

  std::cout << "cylinder: cameras within " << 1e3 * worst_position << " mm and " << worst_rotation << " deg; centre "
            << 1e3 * centre_error << " mm, axis " << axis_error_deg << " deg\n";

  const TruthComparison with_truth = CompareWithTruth(DerenderAnalytic(truth, DerenderOptions()).samples, *material);
  const TruthComparison with_aligned =
      CompareWithTruth(DerenderAnalytic(result.session, DerenderOptions()).samples, *material);
  for (int c = 0; c < 3; ++c) {
    std::cout << "channel " << c << ": median error " << 100 * with_aligned.overall.median[c] << " % aligned, "
              << 100 * with_truth.overall.median[c] << " % true pose\n";
    EXPECT_LT(with_aligned.overall.median[c], 1.5 * with_truth.overall.median[c]) << "channel " << c;
  }
}

}  // namespace
}  // namespace ibrdf
