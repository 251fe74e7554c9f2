// Local-plane normals: accuracy against the exact normals of synthetic scans (sphere, ellipsoid) at
// realistic scanner noise, compared with face normals; the same normals 10 km from the origin; and
// degenerate neighbourhoods that must give a clear result, never NaN.
#include "scan/local_plane_normals.h"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "core/error.h"
#include "scan/range_grid.h"
#include "synth/synthetic_scan.h"
#include "tests/scan/scan_test_util.h"

namespace ibrdf {
namespace {

using testing::AngleBetween;
using testing::Median;

struct Errors {
  double local_plane_median = 0.0;  // radians
  double face_median = 0.0;
};

// A noisy range scan of an ellipsoid, tessellated; errors of local-plane normals at the points and of
// face normals at the face centroids, both against the exact normal.
Errors MeasureErrors(const SyntheticRangeScanOptions& synth) {
  ScanMesh mesh = MakeSyntheticRangeScan(synth);
  TessellateRangeGrid(RangeGridOptions(), &mesh);
  const LocalPlaneResult result = FitLocalPlanes(mesh, LocalPlaneOptions());
  std::vector<double> local, face;
  // Corner cells of the scan's rim may have too few neighbours; everything else is fitted.
  EXPECT_GT(result.fitted, 0.99 * mesh.points.size());
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    if (result.source[i] != NormalSource::kFitted) continue;
    local.push_back(AngleBetween(result.normals[i], TrueEllipsoidNormal(synth, mesh.points[i])));
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& v = mesh.faces[f];
    const Eigen::Vector3d centre = (mesh.points[v[0]] + mesh.points[v[1]] + mesh.points[v[2]]) / 3.0;
    face.push_back(AngleBetween(FaceNormal(mesh, f), TrueEllipsoidNormal(synth, centre)));
  }
  return {Median(local), Median(face)};
}

TEST(LocalPlaneNormals, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(LocalPlaneOptions().Check(&why)) << why;
  LocalPlaneOptions bad;
  bad.min_neighbours = 2;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "min_neighbours >= 3 failed: min_neighbours = 2");
}

// 0.1 mm noise on a 100 mm sphere sampled every 1 mm: the fit averages the noise away.
TEST(LocalPlaneNormals, SphereBeatsFaceNormalsSeveralTimes) {
  SyntheticRangeScanOptions synth;  // 100 mm sphere, 100 x 100 grid, 0.1 mm noise
  const Errors errors = MeasureErrors(synth);
  RecordProperty("local_plane_median_deg", std::to_string(errors.local_plane_median * 180 / M_PI));
  RecordProperty("face_median_deg", std::to_string(errors.face_median * 180 / M_PI));
  EXPECT_LT(errors.local_plane_median * 3.0, errors.face_median)
      << "local plane " << errors.local_plane_median * 180 / M_PI << " deg, faces " << errors.face_median * 180 / M_PI
      << " deg";
  EXPECT_LT(errors.local_plane_median, 2.0 * M_PI / 180);
}

TEST(LocalPlaneNormals, EllipsoidBeatsFaceNormalsSeveralTimes) {
  SyntheticRangeScanOptions synth;
  synth.radii = Eigen::Vector3d(0.05, 0.035, 0.025);
  synth.seed = 7;
  const Errors errors = MeasureErrors(synth);
  EXPECT_LT(errors.local_plane_median * 3.0, errors.face_median)
      << "local plane " << errors.local_plane_median * 180 / M_PI << " deg, faces " << errors.face_median * 180 / M_PI
      << " deg";
}

TEST(LocalPlaneNormals, NoiseFreeSphereIsExactToCurvatureBias) {
  SyntheticRangeScanOptions synth;
  synth.noise_m = 0.0;
  const Errors errors = MeasureErrors(synth);
  EXPECT_LT(errors.local_plane_median, 0.2 * M_PI / 180);
}

TEST(LocalPlaneNormals, NormalsPointOutward) {
  SyntheticRangeScanOptions synth;
  ScanMesh mesh = MakeSyntheticRangeScan(synth);
  TessellateRangeGrid(RangeGridOptions(), &mesh);
  const LocalPlaneResult result = FitLocalPlanes(mesh, LocalPlaneOptions());
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    ASSERT_GT(result.normals[i].dot(TrueEllipsoidNormal(synth, mesh.points[i])), 0.5) << i;
  }
  // Without any reference (no faces, no file normals): away from the centroid.
  const LocalPlaneResult bare = FitLocalPlanes(mesh.points, {}, LocalPlaneOptions());
  size_t outward = 0;
  for (size_t i = 0; i < mesh.points.size(); ++i) outward += bare.normals[i].z() > 0;
  EXPECT_GT(outward, 0.95 * mesh.points.size());
}

TEST(LocalPlaneNormals, QualityIsTheResidualAndNeighbourCount) {
  SyntheticRangeScanOptions synth;
  synth.noise_m = 1e-4;
  ScanMesh mesh = MakeSyntheticRangeScan(synth);
  const LocalPlaneResult result = FitLocalPlanes(mesh.points, {}, LocalPlaneOptions());
  // Noise of 0.1 mm along z: the residual is about that, reduced slightly by the fit's freedom.
  EXPECT_GT(result.rms_median_m, 0.6e-4);
  EXPECT_LT(result.rms_median_m, 1.3e-4);
  // Radius 3 x spacing on a square grid: pi * 9 = 28 points, minus boundary effects.
  EXPECT_GE(result.neighbours_median, 20);
  EXPECT_LE(result.neighbours_median, 32);
  EXPECT_NEAR(result.spacing_m, 1e-3, 1e-4);  // 100 mm over 100 cells
  EXPECT_NEAR(result.radius_m, 3e-3, 3e-4);
}

// The same scan 10 km from the origin: the same normals within 1e-6 rad.
TEST(LocalPlaneNormals, TenKilometresFromTheOriginGivesTheSameNormals) {
  SyntheticRangeScanOptions synth;
  synth.cols = synth.rows = 60;
  ScanMesh near_mesh = MakeSyntheticRangeScan(synth);
  TessellateRangeGrid(RangeGridOptions(), &near_mesh);
  ScanMesh far_mesh = near_mesh;
  const Eigen::Vector3d offset(1e4, -7e3, 7.1e3);  // about 14 km
  for (Eigen::Vector3d& p : far_mesh.points) p += offset;
  LocalPlaneOptions options;
  options.radius_m = 3e-3;  // fixed, so only the arithmetic can differ
  const LocalPlaneResult near_result = FitLocalPlanes(near_mesh, options);
  const LocalPlaneResult far_result = FitLocalPlanes(far_mesh, options);
  double worst = 0.0;
  for (size_t i = 0; i < near_mesh.points.size(); ++i) {
    ASSERT_EQ(near_result.neighbours[i], far_result.neighbours[i]) << i;
    worst = std::max(worst, AngleBetween(near_result.normals[i], far_result.normals[i]));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(near_result.rms_median_m, far_result.rms_median_m, 1e-9);
}

TEST(LocalPlaneNormals, CoplanarNeighbourhoodGivesTheExactPlaneNormal) {
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d normal = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) points.push_back(1e-3 * (i * u + j * v));
  }
  LocalPlaneOptions options;
  options.radius_m = 2.5e-3;
  const LocalPlaneResult result = FitLocalPlanes(points, std::vector<Eigen::Vector3d>(points.size(), normal), options);
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(result.source[i], NormalSource::kFitted);
    EXPECT_LT(AngleBetween(result.normals[i], normal), 1e-9);
    EXPECT_LT(result.rms_m[i], 1e-9);  // the eigen-solver's round-off on a 1e-6 m^2 spread
  }
}

TEST(LocalPlaneNormals, CollinearNeighbourhoodIsReportedNotFitted) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(1e-3 * i, 2e-3 * i, 0.0);
  LocalPlaneOptions options;
  options.radius_m = 5e-3;
  const LocalPlaneResult result = FitLocalPlanes(points, {}, options);
  EXPECT_EQ(result.fitted, 0u);
  EXPECT_GE(result.collinear, points.size() - 4);  // two points at each end have too few neighbours
  EXPECT_EQ(result.collinear + result.too_few_neighbours, points.size());
  EXPECT_EQ(result.no_normal, points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(result.source[i], NormalSource::kNone);
    EXPECT_TRUE(result.normals[i].allFinite());
    EXPECT_EQ(result.normals[i], Eigen::Vector3d::Zero());
  }
  // With a reference normal, the unfitted points take it.
  const LocalPlaneResult with_reference =
      FitLocalPlanes(points, std::vector<Eigen::Vector3d>(points.size(), Eigen::Vector3d::UnitZ()), options);
  EXPECT_EQ(with_reference.source[3], NormalSource::kReference);
  EXPECT_EQ(with_reference.normals[3], Eigen::Vector3d::UnitZ());
}

TEST(LocalPlaneNormals, IsolatedPointsGetNoFitAndNoNaN) {
  std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  LocalPlaneOptions options;
  options.radius_m = 0.01;
  const LocalPlaneResult result = FitLocalPlanes(points, {}, options);
  EXPECT_EQ(result.fitted, 0u);
  EXPECT_EQ(result.too_few_neighbours, 4u);
  for (const Eigen::Vector3d& n : result.normals) EXPECT_TRUE(n.allFinite());
  // No points at all: an empty result.
  const LocalPlaneResult empty = FitLocalPlanes(std::vector<Eigen::Vector3d>(), {}, LocalPlaneOptions());
  EXPECT_EQ(empty.points, 0u);
  EXPECT_TRUE(empty.normals.empty());
}

TEST(LocalPlaneNormals, SingleTriangleTakesTheFaceNormal) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}};
  mesh.faces = {{0, 1, 2}};
  const LocalPlaneResult result = FitLocalPlanes(mesh, LocalPlaneOptions());  // default min 5 neighbours
  EXPECT_EQ(result.fitted, 0u);
  for (const Eigen::Vector3d& n : result.normals) {
    EXPECT_TRUE(n.allFinite());
    EXPECT_NEAR(n.z(), 1.0, 1e-12);  // counter-clockwise from +z
  }
  // Allowing a 3-point fit gives the same plane, oriented by the face.
  LocalPlaneOptions three;
  three.min_neighbours = 3;
  three.radius_m = 2e-3;
  const LocalPlaneResult fitted = FitLocalPlanes(mesh, three);
  EXPECT_EQ(fitted.fitted, 3u);
  for (const Eigen::Vector3d& n : fitted.normals) EXPECT_NEAR(n.z(), 1.0, 1e-12);
}

TEST(LocalPlaneNormals, DuplicatePointsOnlyAreNotAPlane) {
  std::vector<Eigen::Vector3d> points(10, Eigen::Vector3d(1, 2, 3));
  LocalPlaneOptions options;
  options.radius_m = 1e-3;
  const LocalPlaneResult result = FitLocalPlanes(points, {}, options);
  EXPECT_EQ(result.fitted, 0u);
  for (const Eigen::Vector3d& n : result.normals) EXPECT_TRUE(n.allFinite());
}

TEST(LocalPlaneNormals, BadOptionsAreAnError) {
  LocalPlaneOptions options;
  options.radius_m = -1.0;
  EXPECT_THROW(FitLocalPlanes(std::vector<Eigen::Vector3d>(), {}, options), Error);
}

}  // namespace
}  // namespace ibrdf
