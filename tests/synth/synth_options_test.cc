// The synth options, split by concern: defaults are valid, each part's Check names the constraint
// that failed, and the constraints between parts (camera, light, ring, scanner outside the sample).
#include "synth/synth_options.h"

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

// Check fails and `why` names `field`.
void ExpectFailureNaming(const SynthOptions& options, const std::string& field) {
  std::string why;
  EXPECT_FALSE(options.Check(&why)) << field;
  EXPECT_NE(why.find(field), std::string::npos) << why;
}

TEST(SynthOptions, DefaultOptionsOfEveryPartAreValid) {
  std::string why;
  EXPECT_TRUE(SynthSceneOptions().Check(&why)) << why;
  EXPECT_TRUE(SynthRigOptions().Check(&why)) << why;
  EXPECT_TRUE(CameraEffects().Check(&why)) << why;
  EXPECT_TRUE(SynthRadiometryOptions().Check(&why)) << why;
  EXPECT_TRUE(SynthTargetOptions().Check(&why)) << why;
  SynthTargetOptions targets;
  targets.enabled = true;
  targets.light_photos = 3;
  EXPECT_TRUE(targets.Check(&why)) << why;
  EXPECT_TRUE(SynthScanOptions().Check(&why)) << why;
  EXPECT_TRUE(SynthOptions().Check(&why)) << why;
}

TEST(SynthOptions, EachPartNamesTheFailingConstraint) {
  SynthOptions options;
  options.rig.num_photos = 0;
  ExpectFailureNaming(options, "num_photos");
  options = SynthOptions();
  options.scene.fill_light = 1.0;
  ExpectFailureNaming(options, "fill_light");
  options = SynthOptions();
  options.effects.bits = 5;
  ExpectFailureNaming(options, "bits");
  options = SynthOptions();
  options.radiometry.brackets = 0;
  ExpectFailureNaming(options, "brackets");
  options = SynthOptions();
  options.targets.enabled = true;
  options.targets.light_photos = 2;
  options.targets.light_marker_first_id = 5;  // among the ring's ids
  ExpectFailureNaming(options, "light_marker_first_id");
}

TEST(SynthOptions, TargetFieldsAreUnusedWhenTargetsAreOff) {
  SynthOptions options;
  options.targets.ring_count = 0;
  options.targets.ring_radius = 0.0;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.targets.enabled = true;
  EXPECT_FALSE(options.Check(&why));
}

TEST(SynthOptions, ConstraintsBetweenParts) {
  SynthOptions options;
  options.rig.camera_distance = 0.05;  // inside 1.5 sample radii
  ExpectFailureNaming(options, "camera_distance");
  options = SynthOptions();
  options.scene.light_distance = 0.03;
  ExpectFailureNaming(options, "light_distance");
  options = SynthOptions();
  options.targets.enabled = true;
  options.targets.ring_radius = 0.05;  // under the sphere's radius plus a marker
  ExpectFailureNaming(options, "ring_radius");
  options = SynthOptions();
  options.scene.shape = SynthShape::kDent;
  ExpectFailureNaming(options, "targets.enabled");
  options.targets.enabled = true;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.scan.truth_mesh_spacing_m = 0.01;  // above a tenth of the dent's size
  ExpectFailureNaming(options, "truth_mesh_spacing_m");
}

// The rigs: names round-trip; the dome reads the arc's range as angles in [0, 180]; targets only on
// the arc.
TEST(SynthOptions, RigsAreChecked) {
  for (SynthRig rig : {SynthRig::kArc, SynthRig::kDome, SynthRig::kTurntable}) {
    EXPECT_EQ(SynthRigFromName(SynthRigName(rig)), rig);
  }
  EXPECT_THROW(SynthRigFromName("gantry"), Error);
  SynthOptions options;
  options.rig.rig = SynthRig::kDome;
  options.rig.arc_end_deg = 200.0;
  ExpectFailureNaming(options, "arc_end_deg");
  options = SynthOptions();
  options.rig.rig = SynthRig::kTurntable;
  options.rig.turntable_phase_deg = 0.0;
  ExpectFailureNaming(options, "turntable_phase_deg");
  options = SynthOptions();
  options.rig.rig = SynthRig::kDome;
  options.targets.enabled = true;
  ExpectFailureNaming(options, "targets.enabled");
  options.rig.rig = SynthRig::kArc;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
}

TEST(SynthOptions, ShapeNamesRoundTrip) {
  for (SynthShape shape : {SynthShape::kNone, SynthShape::kSquash, SynthShape::kPot, SynthShape::kDent}) {
    EXPECT_EQ(SynthShapeFromName(SynthShapeName(shape)), shape);
  }
  EXPECT_THROW(SynthShapeFromName("cube"), Error);
}

// --camera-positions: a list of [x, y, z] or a capture-check.json's suggestions; anything else is an
// Error naming the file and the entry.
TEST(SynthOptions, CameraPositionsFromAListOrACaptureCheck) {
  testing::ScratchDir dir;
  std::ofstream(dir / "list.json") << "[[0.1, 0.2, 0.3], [1, 2, 3]]";
  std::ofstream(dir / "check.json") << R"({"format": "ibrdf-capture-check", "suggestions": [{"position": [0.5, 0, 0.4]}]})";
  std::ofstream(dir / "bad.json") << "[[0.1, 0.2]]";
  const std::vector<Eigen::Vector3d> list = ReadCameraPositions(dir / "list.json");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1], Eigen::Vector3d(1, 2, 3));
  const std::vector<Eigen::Vector3d> check = ReadCameraPositions(dir / "check.json");
  ASSERT_EQ(check.size(), 1u);
  EXPECT_EQ(check[0], Eigen::Vector3d(0.5, 0, 0.4));
  try {
    ReadCameraPositions(dir / "bad.json");
    FAIL() << "a pair was read as a position";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/0: expected [x, y, z]"), std::string::npos) << e.what();
  }
  // Only the arc takes them.
  SynthRigOptions rig;
  rig.extra_camera_positions = list;
  std::string why;
  EXPECT_TRUE(rig.Check(&why)) << why;
  rig.rig = SynthRig::kDome;
  EXPECT_FALSE(rig.Check(&why));
}

}  // namespace
}  // namespace ibrdf
