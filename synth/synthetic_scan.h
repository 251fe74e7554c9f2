// Synthetic scans with known normals everywhere, from a generator with options and a fixed seed
// (COLMAP's scene/synthetic.h in spirit): an orthographic range image of an ellipsoid (a sphere when
// the radii agree) with scanner noise along the viewing direction, closed UV-sampled meshes of an
// ellipsoid (convex) and a torus (not convex), and a simulated range scanner for any surface given as
// a ray caster (synth's irregular samples), whose views are written as PLY range grids.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/rigid3.h"
#include "scan/scan_mesh.h"

namespace ibrdf {

struct SyntheticRangeScanOptions {
  Eigen::Vector3d radii = Eigen::Vector3d(0.05, 0.05, 0.05);  // semi-axes, metres (a 100 mm sphere)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();           // centre of the ellipsoid, metres
  int cols = 100, rows = 100;                                 // range image over the silhouette's bounding box
  double noise_m = 1e-4;             // Gaussian noise along the viewing direction (z), one sigma
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

// A range scanner seen as a pinhole range camera: every grid cell is one ray from the scanner's centre
// and measures the distance along it to the first surface hit, with Gaussian noise along the ray.
// Views: `views_around` on a ring around the sample (evenly spaced in azimuth, looking at its centre
// from `around_elevation_deg` above the horizontal) and optionally one from straight above.
struct RangeScannerOptions {
  int views_around = 6;
  double around_elevation_deg = 20.0;
  bool view_above = true;
  double distance_m = 0.5;           // scanner centre to the sample centre
  double spacing_m = 0.0007;         // grid spacing (between neighbouring rays) at the sample centre's distance
  double noise_m = 1e-4;             // Gaussian range noise along the ray, one sigma
  double max_view_angle_deg = 75.0;  // cells whose surface is seen more obliquely are empty
  uint64_t seed = 1;

  bool Check(std::string* why) const;
};

// The first hit of a ray (unit direction) on a surface: its distance and outward unit normal. False
// for a miss.
using RayCaster = std::function<bool(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* t,
                                     Eigen::Vector3d* normal)>;

// One range grid per view of the surface inside the sphere (`center`, `radius`, world frame), points
// mapped into the scanner's frame by `scan_from_world` (in double: scanner coordinates may lie
// kilometres from the origin). No faces; `grid` set. Views run in parallel; the result does not depend
// on the thread count.
std::vector<ScanMesh> SimulateRangeScans(const RayCaster& surface, const Eigen::Vector3d& center, double radius,
                                         const RangeScannerOptions& options, const Rigid3d& scan_from_world);

// Writes one range grid as a binary PLY with the Cyberware range_grid element (obj_info num_cols and
// num_rows; one list of 0 or 1 vertex index per cell, row-major), as raw scanner software does;
// ReadPly reads it back. Atomic.
void WriteRangeGridPly(const std::string& path, const ScanMesh& grid);

}  // namespace ibrdf
