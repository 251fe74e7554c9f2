// The convexity report: a convex sample needs no shadow rays; a torus does; degenerate inputs give a
// clear answer.
#include "scan/convexity.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "synth/synthetic_scan.h"

namespace ibrdf {
namespace {

TEST(Convexity, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ConvexityOptions().Check(&why)) << why;
  EXPECT_TRUE(ConvexityReport().needs_shadow_rays);  // reads as "not known convex" until it ran
}

TEST(Convexity, NoisyEllipsoidIsConvex) {
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.035, 0.025), 30, 60);
  AddNormalNoise(1e-4, 3, &mesh);
  const ConvexityReport report = ReportConvexity(mesh, ConvexityOptions());
  EXPECT_FALSE(report.needs_shadow_rays) << report.BriefReport();
  EXPECT_GT(report.fraction_within, 0.999);
  EXPECT_LT(report.max_distance_m, 1e-3);  // noise and chord sag only
  EXPECT_TRUE(report.warning.empty());
  ASSERT_EQ(report.distance_m.size(), mesh.points.size());
  for (double d : report.distance_m) EXPECT_GE(d, 0.0);
}

TEST(Convexity, TorusNeedsShadowRays) {
  const double R = 0.04, r = 0.01;
  const ScanMesh mesh = MakeTorus(R, r, 60, 24);
  const ConvexityReport report = ReportConvexity(mesh, ConvexityOptions());
  EXPECT_TRUE(report.needs_shadow_rays);
  EXPECT_FALSE(report.warning.empty());
  // The innermost ring lies 2 r inside the hull (the hull's top and bottom are the planes z = +-r,
  // but the nearest hull face of the inner equator is the side: distance from R - r to ... at least r).
  EXPECT_GT(report.max_distance_m, 0.9 * r);
  // About half of the surface faces the hole.
  EXPECT_GT(report.fraction_within, 0.2);
  EXPECT_LT(report.fraction_within, 0.7);
  const nlohmann::json json = report.ToJson();
  EXPECT_EQ(json.at("needs_shadow_rays"), true);
}

TEST(Convexity, FarFromTheOriginGivesTheSameDistances) {
  ScanMesh mesh = MakeTorus(0.04, 0.01, 30, 12);
  const ConvexityReport near_report = ReportConvexity(mesh, ConvexityOptions());
  for (Eigen::Vector3d& p : mesh.points) p += Eigen::Vector3d(1e4, 1e4, -1e4);
  const ConvexityReport far_report = ReportConvexity(mesh, ConvexityOptions());
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    EXPECT_NEAR(near_report.distance_m[i], far_report.distance_m[i], 1e-9);
  }
}

TEST(Convexity, FlatSampleIsConvexWithoutHull) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1e-2, 0, 0}, {0, 1e-2, 0}, {1e-2, 1e-2, 0}};
  mesh.faces = {{0, 1, 3}, {0, 3, 2}};
  const ConvexityReport report = ReportConvexity(mesh, ConvexityOptions());
  EXPECT_TRUE(report.flat);
  EXPECT_FALSE(report.needs_shadow_rays);
  EXPECT_EQ(report.fraction_within, 1.0);
}

TEST(Convexity, TooFewPointsIsAnError) {
  ScanMesh mesh;
  mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  EXPECT_THROW(ReportConvexity(mesh, ConvexityOptions()), Error);
}

}  // namespace
}  // namespace ibrdf
