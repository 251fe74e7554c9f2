// Cleaning: each step removes what it should, counts it, and leaves good geometry alone.
#include "scan/mesh_clean.h"

#include <gtest/gtest.h>

#include "synth/synthetic_scan.h"

namespace ibrdf {
namespace {

CleanOptions OnlyStructural() {
  CleanOptions options;
  options.remove_outliers = false;
  options.min_piece_fraction = 0.0;
  return options;
}

TEST(MeshClean, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(CleanOptions().Check(&why)) << why;
  CleanOptions bad;
  bad.tiny_face_fraction = 2.0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "tiny_face_fraction < 1.0 failed: tiny_face_fraction = 2");
}

TEST(MeshClean, CleanSphereLosesNothing) {
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.05, 0.05), 20, 40);
  const size_t points = mesh.points.size(), faces = mesh.faces.size();
  const CleanReport report = CleanMesh(CleanOptions(), &mesh);
  EXPECT_EQ(mesh.points.size(), points);
  EXPECT_EQ(mesh.faces.size(), faces);
  EXPECT_EQ(report.pieces, 1u);
  for (const auto& [step, count] : report.removed) EXPECT_EQ(count, 0u) << step;
}

TEST(MeshClean, MergesDuplicatePointsAndDropsTheFacesTheyCollapse) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};  // 4 duplicates 1
  mesh.faces = {{0, 1, 2}, {4, 3, 2}, {1, 4, 3}};                         // the last collapses onto an edge
  const CleanReport report = CleanMesh(OnlyStructural(), &mesh);
  EXPECT_EQ(report.removed.at("duplicate_points"), 1u);
  EXPECT_EQ(report.removed.at("degenerate_faces"), 1u);
  EXPECT_EQ(mesh.points.size(), 4u);
  ASSERT_EQ(mesh.faces.size(), 2u);
  EXPECT_EQ(mesh.faces[1], Eigen::Vector3i(1, 3, 2));
}

TEST(MeshClean, RemovesDegenerateRepeatedAndTinyFaces) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {1, 1, 0}, {1, 1e-6, 0}};
  mesh.faces = {{0, 1, 2},   // good
                {1, 3, 4},   // good
                {0, 1, 3},   // zero area (collinear corners)
                {2, 1, 0},   // the same corners as the first
                {0, 5, 1}};  // a sliver: area 5e-7 against a median of 0.5
  const CleanReport report = CleanMesh(OnlyStructural(), &mesh);
  EXPECT_EQ(report.removed.at("degenerate_faces"), 2u);
  EXPECT_EQ(report.removed.at("tiny_faces"), 1u);
  EXPECT_EQ(report.removed.at("unreferenced_points"), 1u);  // point 5
  EXPECT_EQ(mesh.faces.size(), 2u);
}

TEST(MeshClean, RemovesNonManifoldFaces) {
  ScanMesh mesh;
  // Three triangles on the edge 0-1: the third makes it non-manifold.
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}};
  mesh.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const CleanReport report = CleanMesh(OnlyStructural(), &mesh);
  EXPECT_EQ(report.removed.at("non_manifold_faces"), 1u);
  EXPECT_EQ(mesh.faces.size(), 2u);
}

TEST(MeshClean, RemovesSmallPiecesAndOutliers) {
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.05, 0.05), 20, 40);
  const size_t sphere_faces = mesh.faces.size();
  // A stray triangle 1 m away: a small piece, and its points are statistical outliers too.
  const int n = static_cast<int>(mesh.points.size());
  mesh.points.push_back({1, 0, 0});
  mesh.points.push_back({1.001, 0, 0});
  mesh.points.push_back({1, 0.001, 0});
  mesh.faces.emplace_back(n, n + 1, n + 2);
  CleanOptions pieces_only;
  pieces_only.remove_outliers = false;
  ScanMesh copy = mesh;
  const CleanReport pieces = CleanMesh(pieces_only, &copy);
  EXPECT_EQ(pieces.removed.at("small_piece_faces"), 1u);
  EXPECT_EQ(pieces.removed.at("unreferenced_points"), 3u);
  EXPECT_EQ(copy.faces.size(), sphere_faces);
  const CleanReport all = CleanMesh(CleanOptions(), &mesh);
  EXPECT_EQ(all.removed.at("outlier_points"), 3u);
  EXPECT_EQ(all.removed.at("faces_of_removed_points"), 1u);
  EXPECT_EQ(mesh.faces.size(), sphere_faces);
  EXPECT_EQ(all.pieces, 1u);
}

TEST(MeshClean, SingleTriangleSurvives) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}};
  mesh.faces = {{0, 1, 2}};
  const CleanReport report = CleanMesh(CleanOptions(), &mesh);
  EXPECT_EQ(mesh.faces.size(), 1u);
  EXPECT_EQ(report.pieces, 1u);
}

TEST(MeshClean, IsolatedPointsWithoutFacesAreRemoved) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}};
  const CleanReport report = CleanMesh(OnlyStructural(), &mesh);
  EXPECT_EQ(report.removed.at("unreferenced_points"), 2u);
  EXPECT_TRUE(mesh.points.empty());
}

}  // namespace
}  // namespace ibrdf
