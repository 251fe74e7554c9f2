// Synthetic scans with known normals everywhere, from a generator with options and a fixed seed
// (COLMAP's scene/synthetic.h in spirit): an orthographic range image of an ellipsoid (a sphere when
// the radii agree) with scanner noise along the viewing direction, and closed UV-sampled meshes of an
// ellipsoid (convex) and a torus (not convex).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scan/scan_mesh.h"

namespace ibrdf {

struct SyntheticRangeScanOptions {
  Eigen::Vector3d radii = Eigen::Vector3d(0.05, 0.05, 0.05);  // semi-axes, metres (a 100 mm sphere)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();           // centre of the ellipsoid, metres
  int cols = 100, rows = 100;   // range image over the silhouette's bounding box
  double noise_m = 1e-4;        // Gaussian noise along the viewing direction (z), one sigma
  double max_view_angle_deg = 75.0;  // cells whose surface is seen more obliquely are empty
  uint64_t seed = 1;

  bool Check(std::string* why) const;
};

// The front half (z > 0) of the ellipsoid as seen by a scanner looking down -z: a range grid, no faces.
ScanMesh MakeSyntheticRangeScan(const SyntheticRangeScanOptions& options);

// The exact outward normal of the ellipsoid at the surface point above (x, y) of `p` (front half).
Eigen::Vector3d TrueEllipsoidNormal(const SyntheticRangeScanOptions& options, const Eigen::Vector3d& p);

// A closed ellipsoid, `rings` x `segments` samples in latitude and longitude plus the poles, with its
// exact normals in `normals`; faces counter-clockwise from outside.
ScanMesh MakeUvEllipsoid(const Eigen::Vector3d& radii, int rings, int segments);

// A closed torus around z (major radius R, minor radius r): not convex, its inner side lies up to
// 2 r inside the convex hull.
ScanMesh MakeTorus(double major_radius_m, double minor_radius_m, int rings, int segments);

// Adds Gaussian noise of sigma `noise_m` along each point's normal (the mesh must have normals); the
// normals are kept as the truth.
void AddNormalNoise(double noise_m, uint64_t seed, ScanMesh* mesh);

}  // namespace ibrdf
