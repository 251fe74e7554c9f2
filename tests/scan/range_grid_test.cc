// Range-grid tessellation: grid neighbours become triangles, never across a depth discontinuity.
#include "scan/range_grid.h"

#include <gtest/gtest.h>

#include "scan/ply_io.h"
#include "synth/synthetic_scan.h"
#include "tests/scan/scan_test_util.h"

namespace ibrdf {
namespace {

// A 20 x 20 grid of two planes: the left half at depth 0, the right half 10 mm closer (a step).
ScanMesh StepGrid() {
  ScanMesh mesh;
  mesh.grid.rows = mesh.grid.cols = 20;
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c < 20; ++c) {
      mesh.grid.cell_point.push_back(static_cast<int>(mesh.points.size()));
      mesh.points.emplace_back(1e-3 * c, -1e-3 * r, c < 10 ? 0.0 : 0.01);
    }
  }
  return mesh;
}

TEST(RangeGrid, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(RangeGridOptions().Check(&why)) << why;
  RangeGridOptions bad;
  bad.max_edge_factor = 0.5;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "max_edge_factor > 1.0 failed: max_edge_factor = 0.5");
}

TEST(RangeGrid, FullGridGivesTwoTrianglesPerCell) {
  ScanMesh mesh = StepGrid();
  for (Eigen::Vector3d& p : mesh.points) p.z() = 0.0;  // flat
  const RangeGridReport report = TessellateRangeGrid(RangeGridOptions(), &mesh);
  EXPECT_EQ(mesh.faces.size(), 2u * 19 * 19);
  EXPECT_EQ(report.dropped_depth_discontinuity, 0u);
  EXPECT_NEAR(report.spacing_m, 1e-3, 1e-12);
}

TEST(RangeGrid, NoTriangleAcrossADepthStep) {
  ScanMesh mesh = StepGrid();
  const RangeGridReport report = TessellateRangeGrid(RangeGridOptions(), &mesh);
  EXPECT_EQ(report.dropped_depth_discontinuity, 2u * 19);  // the column of cells across the step
  EXPECT_EQ(mesh.faces.size(), 2u * 19 * 18);
  for (const Eigen::Vector3i& f : mesh.faces) {
    const double z0 = mesh.points[f[0]].z();
    EXPECT_EQ(mesh.points[f[1]].z(), z0);
    EXPECT_EQ(mesh.points[f[2]].z(), z0);
  }
}

TEST(RangeGrid, EmptyCellsGiveOneTriangleOrNone) {
  ScanMesh mesh = StepGrid();
  for (Eigen::Vector3d& p : mesh.points) p.z() = 0.0;
  mesh.grid.cell_point[0] = -1;           // a corner: its cell keeps one triangle
  mesh.grid.cell_point[5 * 20 + 5] = -1;  // an inner hole: four cells lose one triangle each ...
  mesh.grid.cell_point[5 * 20 + 6] = -1;  // ... two holes side by side empty two cells
  TessellateRangeGrid(RangeGridOptions(), &mesh);
  EXPECT_EQ(mesh.faces.size(), 2u * 19 * 19 - 1 - 2 * 2 - 2 * 2);
}

TEST(RangeGrid, FacesPointOutwardOnASphere) {
  SyntheticRangeScanOptions synth;
  synth.cols = synth.rows = 40;
  ScanMesh mesh = MakeSyntheticRangeScan(synth);
  TessellateRangeGrid(RangeGridOptions(), &mesh);
  ASSERT_FALSE(mesh.faces.empty());
  for (size_t f = 0; f < mesh.faces.size(); ++f) ASSERT_GT(FaceNormal(mesh, f).z(), 0.0) << f;
}

TEST(RangeGrid, OrientFacesOutwardFlipsInwardFaces) {
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d(1, 1, 1), 6, 8);
  for (Eigen::Vector3i& f : mesh.faces) std::swap(f[1], f[2]);
  EXPECT_TRUE(OrientFacesOutward(&mesh));
  EXPECT_FALSE(OrientFacesOutward(&mesh));
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& v = mesh.faces[f];
    EXPECT_GT(FaceNormal(mesh, f).dot(mesh.points[v[0]] + mesh.points[v[1]] + mesh.points[v[2]]), 0.0);
  }
}

// The Must-show check on real data: every triangle joins grid neighbours on one surface; none bridges
// a silhouette (the bunny's outline against the background, or the ear in front of the body).
TEST(RangeGrid, BunnyTessellatesWithoutFacesAcrossSilhouettes) {
  IBRDF_REQUIRE_BUNNY();
  for (const char* name : {"bun000.ply", "bun045.ply", "bun090.ply"}) {
    ScanMesh mesh = ReadPly(testing::BunnyDir() + "/" + name);
    const RangeGridReport report = TessellateRangeGrid(RangeGridOptions(), &mesh);
    std::cerr << name << ": " << report.BriefReport() << "\n";
    EXPECT_GT(mesh.faces.size(), 1.5 * report.points) << name;    // nearly two triangles per point
    EXPECT_GT(report.dropped_depth_discontinuity, 100u) << name;  // silhouettes exist and were cut
    // Grid spacing is about 0.75 mm; a face bridging a silhouette would have an edge of centimetres.
    EXPECT_NEAR(report.spacing_m, 0.75e-3, 0.15e-3) << name;
    double longest = 0.0;
    for (const Eigen::Vector3i& f : mesh.faces) {
      for (int k = 0; k < 3; ++k) longest = std::max(longest, (mesh.points[f[k]] - mesh.points[f[(k + 1) % 3]]).norm());
    }
    EXPECT_LE(longest, report.max_edge_used_m) << name;
    EXPECT_LT(longest, 4e-3) << name;
    // Each scan, seen from its scanner (looking down -z), shows its front: faces point to +z.
    size_t towards_scanner = 0;
    for (size_t f = 0; f < mesh.faces.size(); ++f) towards_scanner += FaceNormal(mesh, f).z() > 0.0;
    EXPECT_GT(towards_scanner, 0.9 * mesh.faces.size()) << name;
  }
}

}  // namespace
}  // namespace ibrdf
