// Registration of a scan's marker corners to the markers' known layout.
#include "align/mesh_registration.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

// A ring of `count` 28 mm markers of radius 0.1 m on the plane z = -0.04 (as synth --targets lays
// them), or on a line along x when `collinear`.
std::vector<TargetSpec> Layout(int count, bool collinear = false) {
  std::vector<TargetSpec> layout;
  const double half = 0.014;
  for (int k = 0; k < count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.5) / count;
    const Eigen::Vector3d centre = collinear ? Eigen::Vector3d(-0.1 + 0.05 * k, 0.02, -0.04)
                                             : Eigen::Vector3d(0.1 * std::cos(angle), 0.1 * std::sin(angle), -0.04);
    TargetSpec target;
    target.id = k;
    target.corners = {centre + Eigen::Vector3d(-half, half, 0), centre + Eigen::Vector3d(half, half, 0),
                      centre + Eigen::Vector3d(half, -half, 0), centre + Eigen::Vector3d(-half, -half, 0)};
    layout.push_back(target);
  }
  return layout;
}

// The layout as a scanner with frame scan_from_world would measure it, with Gaussian noise.
std::vector<ScanTargetSpec> Scan(const std::vector<TargetSpec>& layout, const Sim3d& scan_from_world, double noise_m,
                                 uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<ScanTargetSpec> scan;
  for (const TargetSpec& target : layout) {
    ScanTargetSpec measured;
    measured.id = target.id;
    for (int k = 0; k < 4; ++k) {
      measured.corners[k] = scan_from_world * target.corners[k] + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    }
    scan.push_back(measured);
  }
  return scan;
}

Sim3d FarScanner(double offset_m, double scale) {
  return Sim3d(Eigen::Quaterniond(Eigen::AngleAxisd(2.1, Eigen::Vector3d(0.3, -1.0, 0.5).normalized())),
               offset_m * Eigen::Vector3d(0.6, -0.48, 0.64), scale);
}

void ExpectSame(const Sim3d& a, const Sim3d& b, double rotation_tol, double translation_tol, double scale_tol) {
  EXPECT_LT(a.rotation.angularDistance(b.rotation), rotation_tol);
  EXPECT_LT((a.translation - b.translation).norm(), translation_tol);
  EXPECT_NEAR(a.scale, b.scale, scale_tol);
}

TEST(MeshRegistration, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(MeshRegistrationOptions().Check(&why)) << why;
  MeshRegistrationOptions bad;
  bad.min_markers = 2;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "min_markers >= 3 failed: min_markers = 2");
}

TEST(MeshRegistration, RecoversAKnownSimilarityExactly) {
  const std::vector<TargetSpec> layout = Layout(12);
  const Sim3d scan_from_world = FarScanner(3.0, 1000.0);  // a scanner in millimetres, 3 km out
  const MeshRegistration registration =
      RegisterMeshToTargets(Scan(layout, scan_from_world, 0.0), layout, MeshRegistrationOptions(), "test");
  ExpectSame(registration.world_from_mesh, scan_from_world.Inverse(), 1e-12, 1e-9, 1e-12);
  EXPECT_EQ(registration.used_markers, 12);
  EXPECT_LT(registration.rms_m, 1e-9);
}

// Scanner coordinates 10 km out: centring keeps the fit at the noise level.
TEST(MeshRegistration, TenKilometreOffsetKeepsItsDigits) {
  const std::vector<TargetSpec> layout = Layout(12);
  const Sim3d scan_from_world = FarScanner(1e4, 1.0);
  const MeshRegistration exact =
      RegisterMeshToTargets(Scan(layout, scan_from_world, 0.0), layout, MeshRegistrationOptions(), "test");
  ExpectSame(exact.world_from_mesh, scan_from_world.Inverse(), 1e-11, 1e-8, 1e-11);
  EXPECT_LT(exact.rms_m, 1e-8);
  // 0.05 mm noise per coordinate: the corners fit to about that, the transform to a few micrometres at
  // the markers.
  const MeshRegistration noisy =
      RegisterMeshToTargets(Scan(layout, scan_from_world, 5e-5), layout, MeshRegistrationOptions(), "test");
  EXPECT_LT(noisy.rms_m, 1e-4);
  EXPECT_GT(noisy.rms_m, 2e-5);
  const Sim3d error = noisy.world_from_mesh * scan_from_world;  // identity up to noise
  EXPECT_LT(error.rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-3);
  EXPECT_LT((error * Eigen::Vector3d(0.1, 0.0, 0.0) - Eigen::Vector3d(0.1, 0.0, 0.0)).norm(), 3e-5);
  EXPECT_NEAR(error.scale, 1.0, 1e-3);
}

TEST(MeshRegistration, ThreeMarkersAreEnoughTwoAreNot) {
  const std::vector<TargetSpec> layout = Layout(12);
  const Sim3d scan_from_world = FarScanner(10.0, 1.0);
  std::vector<ScanTargetSpec> scan = Scan(layout, scan_from_world, 0.0);
  scan.resize(3);
  const MeshRegistration three = RegisterMeshToTargets(scan, layout, MeshRegistrationOptions(), "test");
  ExpectSame(three.world_from_mesh, scan_from_world.Inverse(), 1e-10, 1e-8, 1e-10);
  scan.resize(2);
  try {
    RegisterMeshToTargets(scan, layout, MeshRegistrationOptions(), "s/session.json: /sample/scan_targets");
    FAIL() << "two markers accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("s/session.json: /sample/scan_targets: only 2 marker(s) shared"),
              std::string::npos)
        << error.what();
  }
  // Ids the layout does not know do not count.
  std::vector<ScanTargetSpec> unknown = Scan(layout, scan_from_world, 0.0);
  for (size_t i = 2; i < unknown.size(); ++i) unknown[i].id += 100;
  EXPECT_THROW(RegisterMeshToTargets(unknown, layout, MeshRegistrationOptions(), "test"), Error);
}

TEST(MeshRegistration, CollinearLayoutIsRefused) {
  const std::vector<TargetSpec> layout = Layout(5, /*collinear=*/true);
  try {
    RegisterMeshToTargets(Scan(layout, FarScanner(1.0, 1.0), 0.0), layout, MeshRegistrationOptions(), "test");
    FAIL() << "collinear layout accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("lie nearly on a line"), std::string::npos) << error.what();
  }
}

// A marker the scanner mismeasured (or that moved) by 5 mm is dropped by the leave-one-out check; the
// rest give the exact transform.
TEST(MeshRegistration, BadMarkerIsDropped) {
  const std::vector<TargetSpec> layout = Layout(12);
  const Sim3d scan_from_world = FarScanner(1e4, 1.0);
  std::vector<ScanTargetSpec> scan = Scan(layout, scan_from_world, 0.0);
  for (Eigen::Vector3d& corner : scan[4].corners) corner += Eigen::Vector3d(0.005, 0.0, -0.002);
  const MeshRegistration registration = RegisterMeshToTargets(scan, layout, MeshRegistrationOptions(), "test");
  EXPECT_EQ(registration.used_markers, 11);
  EXPECT_FALSE(registration.markers[4].used);
  EXPECT_NE(registration.markers[4].dropped_reason.find("outlier"), std::string::npos);
  EXPECT_GT(registration.markers[4].rms_m, 0.004);
  ExpectSame(registration.world_from_mesh, scan_from_world.Inverse(), 1e-10, 1e-8, 1e-10);
  EXPECT_NE(registration.BriefReport().find("dropped marker 4"), std::string::npos);
  // Every marker off (a wrong layout): refused, not silently "fitted".
  std::vector<ScanTargetSpec> wrong = Scan(layout, scan_from_world, 0.0);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.004);
  for (ScanTargetSpec& target : wrong) {
    for (Eigen::Vector3d& corner : target.corners) corner += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  EXPECT_THROW(RegisterMeshToTargets(wrong, layout, MeshRegistrationOptions(), "test"), Error);
}

TEST(MeshRegistration, RigidModeKeepsUnitScale) {
  const std::vector<TargetSpec> layout = Layout(8);
  MeshRegistrationOptions options;
  options.estimate_scale = false;
  const MeshRegistration registration =
      RegisterMeshToTargets(Scan(layout, FarScanner(5.0, 1.0), 1e-5), layout, options, "test");
  EXPECT_EQ(registration.world_from_mesh.scale, 1.0);
  EXPECT_LT(registration.rms_m, 3e-5);
}

}  // namespace
}  // namespace ibrdf
