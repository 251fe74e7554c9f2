// The Embree mesh sample: hits against the exact sphere, hits exactly on edges and vertices, tangent
// and grazing rays (a hit or a miss, never NaN), the three ray modes agreeing, a mesh 10 km from the
// origin and in millimetres, shadow rays, inside/outside, and a mesh without normals.
#include "derender/mesh_sample.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "synth/synthetic_scan.h"

namespace ibrdf {
namespace {

// A regular octahedron with unit "radius": vertices on the axes, exact normals (the vertex
// directions), 8 faces counter-clockwise from outside.
ScanMesh Octahedron() {
  ScanMesh mesh;
  mesh.points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.normals = mesh.points;
  mesh.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return mesh;
}

void ExpectFiniteHit(const SurfaceHit& hit) {
  EXPECT_TRUE(std::isfinite(hit.t));
  EXPECT_TRUE(hit.point.allFinite());
  EXPECT_TRUE(hit.normal.allFinite());
  EXPECT_TRUE(hit.geometric_normal.allFinite());
}

TEST(MeshSample, UvSphereHitsMatchTheSphere) {
  const double radius = 0.04;
  const MeshSample mesh(MakeUvEllipsoid(Eigen::Vector3d::Constant(radius), 90, 180), Sim3d(), "uv sphere");
  const SphereSample sphere(Eigen::Vector3d::Zero(), radius);
  // Rays from a camera 0.8 m away, over the whole disc the sphere covers.
  const Eigen::Vector3d camera(0.3, -0.2, 0.7);
  double worst_t = 0.0, worst_normal = 0.0;
  int hits = 0;
  for (int i = -20; i <= 20; ++i) {
    for (int j = -20; j <= 20; ++j) {
      const Eigen::Vector3d target(0.95 * radius * i / 20.0, 0.95 * radius * j / 20.0, 0.0);
      const Eigen::Vector3d direction = (target - camera).normalized();
      SurfaceHit exact, hit;
      const bool on_sphere = sphere.Intersect(camera, direction, &exact);
      const bool on_mesh = mesh.Intersect(camera, direction, &hit);
      if (!on_sphere || !on_mesh) continue;
      ++hits;
      ExpectFiniteHit(hit);
      EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-12);
      EXPECT_GT(hit.geometric_normal.dot(hit.normal), 0.99);
      // Where the view is not grazing: a facet spans at most a 2 x 2 degree cell, so it lies within
      // r (1 - cos 1.42 deg) = 12.2 um of the sphere, and along a ray at most 1 / 0.2 times that.
      if (-direction.dot(exact.normal) > 0.2) {
        worst_t = std::max(worst_t, std::abs(hit.t - exact.t));
        worst_normal = std::max(worst_normal, std::acos(std::min(1.0, hit.normal.dot(exact.normal))));
      }
      EXPECT_NEAR((hit.point - (camera + hit.t * direction)).norm(), 0.0, 1e-12);
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_LT(worst_t, 12.2e-6 / 0.2);
  EXPECT_LT(worst_normal, 0.2 * M_PI / 180.0);
}

TEST(MeshSample, RaysThroughVerticesAndEdgesHit) {
  const MeshSample mesh(Octahedron(), Sim3d(), "octahedron");
  SurfaceHit hit;
  // Exactly at the vertex (0, 0, 1), where four faces meet, from straight above and obliquely.
  ASSERT_TRUE(mesh.Intersect(Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(0, 0, -1), &hit));
  ExpectFiniteHit(hit);
  EXPECT_NEAR(hit.t, 2.0, 1e-12);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-9);
  ASSERT_TRUE(mesh.Intersect(Eigen::Vector3d(1, 1, 2), Eigen::Vector3d(-1, -1, -1).normalized(), &hit));
  ExpectFiniteHit(hit);
  EXPECT_NEAR((hit.point - Eigen::Vector3d(0, 0, 1)).norm(), 0.0, 1e-9);
  // Exactly through the midpoint of the edge from (1, 0, 0) to (0, 0, 1), shared by two faces: the
  // robust traversal cannot let it slip between them.
  const Eigen::Vector3d midpoint(0.5, 0, 0.5);
  for (const Eigen::Vector3d& from :
       {Eigen::Vector3d(2, 0, 2), Eigen::Vector3d(0.5, 3, 0.5), Eigen::Vector3d(2, 1, 0.5)}) {
    ASSERT_TRUE(mesh.Intersect(from, (midpoint - from).normalized(), &hit)) << from.transpose();
    ExpectFiniteHit(hit);
    EXPECT_NEAR((hit.point - midpoint).norm(), 0.0, 1e-9);
    // Half-way between two vertex normals.
    EXPECT_NEAR((hit.normal - Eigen::Vector3d(1, 0, 1).normalized()).norm(), 0.0, 1e-9);
  }
  // A dense sweep of rays across the edge lines of the upper faces: every one hits.
  int missed = 0;
  for (int k = 0; k <= 1000; ++k) {
    const double s = k / 1000.0;
    const Eigen::Vector3d on_edge(1.0 - s, 0.0, s);  // the edge x + z = 1 in the plane y = 0
    missed += !mesh.Intersect(on_edge + Eigen::Vector3d(0.3, 0, 2), -Eigen::Vector3d(0.3, 0, 2).normalized(), &hit);
  }
  EXPECT_EQ(missed, 0);
}

TEST(MeshSample, TangentAndGrazingRaysNeverGiveNaN) {
  const MeshSample octahedron(Octahedron(), Sim3d(), "octahedron");
  SurfaceHit hit;
  // In the plane of the face (1,0,0)-(0,1,0)-(0,0,1): x + y + z = 1, along an edge of it.
  const Eigen::Vector3d along_edge = (Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(1, 0, 0)).normalized();
  if (octahedron.Intersect(Eigen::Vector3d(1, 0, 0) - 2.0 * along_edge, along_edge, &hit)) ExpectFiniteHit(hit);
  // Inside the face's plane, through the face's interior.
  const Eigen::Vector3d in_plane = (Eigen::Vector3d(1, 1, -2)).normalized();
  if (octahedron.Intersect(Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3) - 3.0 * in_plane, in_plane, &hit)) {
    ExpectFiniteHit(hit);
  }
  // Tangent to a UV sphere and grazing it, at many angles.
  const double radius = 0.04;
  const MeshSample sphere(MakeUvEllipsoid(Eigen::Vector3d::Constant(radius), 30, 60), Sim3d(), "uv sphere");
  int found = 0;
  for (int k = 0; k < 200; ++k) {
    // The equator is a 60-gon between 0.99863 r (mid-edge) and r (vertices): straddle it.
    const double offset = radius * (0.998 + 0.003 * k / 200.0);
    const double angle = 0.1 * k;
    const Eigen::Vector3d side(std::cos(angle), std::sin(angle), 0.0);
    if (sphere.Intersect(Eigen::Vector3d(0, 0, 1) + offset * side, Eigen::Vector3d(0, 0, -1), &hit)) {
      ++found;
      ExpectFiniteHit(hit);
      EXPECT_TRUE(hit.normal.isZero(0.0) || std::abs(hit.normal.norm() - 1.0) < 1e-9);
    }
  }
  EXPECT_GT(found, 0);
  EXPECT_LT(found, 200);
}

TEST(MeshSample, RayModesAgree) {
  MeshSample mesh(MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.04, 0.03), 40, 80), Sim3d(), "ellipsoid");
  const Eigen::Vector3d camera(0.1, 0.2, 0.6);
  std::vector<Eigen::Vector3d> directions;
  for (int i = 0; i < 203; ++i) {
    directions.push_back((Eigen::Vector3d(-0.06 + 0.12 * i / 202.0, 0.01, 0.0) - camera).normalized());
  }
  std::vector<SurfaceHit> reference(directions.size());
  std::unique_ptr<bool[]> reference_found(new bool[directions.size()]);
  for (size_t i = 0; i < directions.size(); ++i)
    reference_found[i] = mesh.Intersect(camera, directions[i], &reference[i]);
  for (MeshSample::RayMode mode :
       {MeshSample::RayMode::kSingle, MeshSample::RayMode::kPacket8, MeshSample::RayMode::kStream}) {
    mesh.set_ray_mode(mode);
    std::vector<SurfaceHit> hits(directions.size());
    std::unique_ptr<bool[]> found(new bool[directions.size()]);
    mesh.IntersectBatch(camera, directions.data(), directions.size(), hits.data(), found.get());
    for (size_t i = 0; i < directions.size(); ++i) {
      ASSERT_EQ(found[i], reference_found[i]) << "mode " << int(mode) << " ray " << i;
      if (found[i]) {
        EXPECT_EQ(hits[i].face, reference[i].face);
        EXPECT_NEAR(hits[i].t, reference[i].t, 1e-12);
      }
    }
  }
}

// The same mesh 10 km from the origin (in the file, or moved by world_from_mesh), and in
// millimetres with scale 0.001, gives the same hits as at the origin: to 1e-9 m, far below float's
// 1 mm at 10 km.
TEST(MeshSample, FarFromOriginAndScaledKeepPrecision) {
  const ScanMesh near_mesh = MakeUvEllipsoid(Eigen::Vector3d(0.05, 0.04, 0.03), 40, 80);
  const Eigen::Vector3d far(1e4, -1e4, 2e3);
  ScanMesh far_mesh = near_mesh;
  for (Eigen::Vector3d& p : far_mesh.points) p += far;
  ScanMesh mm_mesh = near_mesh;
  for (Eigen::Vector3d& p : mm_mesh.points) p *= 1000.0;
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  const MeshSample near_sample(near_mesh, Sim3d(), "near");
  const MeshSample far_file(far_mesh, Sim3d(), "far in the file");
  const MeshSample far_moved(near_mesh, Sim3d(Eigen::Quaterniond::Identity(), far, 1.0), "far by world_from_mesh");
  const MeshSample millimetres(mm_mesh, Sim3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), 1e-3), "mm");
  const MeshSample rotated(near_mesh, Sim3d(rotation, far, 1.0), "rotated and far");
  const Eigen::Vector3d camera(0.1, 0.2, 0.6);
  int hits = 0;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d direction = (Eigen::Vector3d(-0.05 + 0.1 * i / 49.0, 0.013, 0.0) - camera).normalized();
    SurfaceHit a, b, c, d, e;
    const bool hit = near_sample.Intersect(camera, direction, &a);
    ASSERT_EQ(far_file.Intersect(camera + far, direction, &b), hit);
    ASSERT_EQ(far_moved.Intersect(camera + far, direction, &c), hit);
    ASSERT_EQ(millimetres.Intersect(camera, direction, &d), hit);
    ASSERT_EQ(rotated.Intersect(rotation * camera + far, rotation * direction, &e), hit);
    if (!hit) continue;
    ++hits;
    for (const SurfaceHit* other : {&b, &c, &e}) {
      EXPECT_NEAR(other->t, a.t, 1e-9);
      EXPECT_NEAR((other->point - far - (other == &e ? Eigen::Vector3d(rotation * a.point) : a.point)).norm(), 0.0,
                  1e-9);
    }
    EXPECT_NEAR(d.t, a.t, 1e-9);
    EXPECT_NEAR((b.normal - a.normal).norm(), 0.0, 1e-9);
    EXPECT_NEAR((e.normal - rotation * a.normal).norm(), 0.0, 1e-9);
  }
  EXPECT_GT(hits, 20);
  EXPECT_NEAR((far_moved.BoundingCenter() - far).norm(), 0.0, 1e-6);
}

TEST(MeshSample, ShadowRaysAndInside) {
  const MeshSample mesh(MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 30, 60), Sim3d(), "sphere");
  EXPECT_TRUE(mesh.Contains(Eigen::Vector3d::Zero()));
  EXPECT_FALSE(mesh.Contains(Eigen::Vector3d(0.1, 0, 0)));
  // Through the sphere: blocked; beside it, and from its surface outwards: free.
  EXPECT_TRUE(mesh.Occluded(Eigen::Vector3d(-0.1, 0, 0), Eigen::Vector3d(0.1, 0, 0)));
  EXPECT_FALSE(mesh.Occluded(Eigen::Vector3d(-0.1, 0.05, 0), Eigen::Vector3d(0.1, 0.05, 0)));
  SurfaceHit hit;
  ASSERT_TRUE(mesh.Intersect(Eigen::Vector3d(0.5, 0.01, 0.02), Eigen::Vector3d(-1, 0, 0), &hit));
  EXPECT_FALSE(mesh.Occluded(hit.point, Eigen::Vector3d(1.2, 0.3, 0.1)));
  EXPECT_TRUE(mesh.Occluded(hit.point, Eigen::Vector3d(-1.2, 0.0, 0.0)));  // through the solid
  // A torus shadows itself: from the inner side of the ring, across the hole, the far side blocks.
  const MeshSample torus(MakeTorus(0.05, 0.015, 48, 96), Sim3d(), "torus");
  EXPECT_TRUE(torus.Occluded(Eigen::Vector3d(-0.0349, 0, 0), Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_FALSE(torus.Occluded(Eigen::Vector3d(-0.0349, 0, 0), Eigen::Vector3d(0, 0, 0.5)));
}

TEST(MeshSample, MeshWithoutNormalsOrFacesIsAnError) {
  ScanMesh mesh = Octahedron();
  mesh.normals.clear();
  try {
    MeshSample sample(mesh, Sim3d(), "scan.ply");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scan.ply"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("normals"), std::string::npos) << e.what();
  }
  ScanMesh points = Octahedron();
  points.faces.clear();
  EXPECT_THROW(MeshSample(points, Sim3d(), "points.ply"), Error);
}

TEST(QuadOccluders, BlockOnlyBeforeTheLimit) {
  const QuadOccluders quads(
      {{Eigen::Vector3d(-1, -1, 1), Eigen::Vector3d(1, -1, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(-1, 1, 1)}});
  EXPECT_EQ(quads.NumQuads(), 1u);
  EXPECT_TRUE(quads.Blocks(Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(0, 0, -1), 5.0));
  EXPECT_FALSE(quads.Blocks(Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(0, 0, -1), 1.5));
  EXPECT_FALSE(quads.Blocks(Eigen::Vector3d(2, 0, 3), Eigen::Vector3d(0, 0, -1), 5.0));
}

}  // namespace
}  // namespace ibrdf
