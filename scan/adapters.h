// Narrow adapters to the third-party libraries of the scan stage. They speak Eigen and ScanMesh only;
// each library lives in one translation unit (pcl_adapters.cc, cgal_adapters.cc,
// openmesh_adapters.cc), since PCL and CGAL compile slowly. Internal to scan/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scan/scan_mesh.h"

namespace ibrdf::scan_adapters {

// --- OpenMesh (openmesh_adapters.cc)

// Reads OBJ, OFF or STL (ASCII or binary) through OpenMesh's readers; polygons are triangulated.
// Throws Error naming the file when OpenMesh cannot read it.
ScanMesh ReadMeshFile(const std::string& path);

// Adds the faces one by one to an OpenMesh TriMesh, which refuses any face that would make an edge or
// a vertex non-manifold; returns keep[f] = false for the refused faces.
std::vector<bool> ManifoldFaces(const ScanMesh& mesh);

// --- PCL (pcl_adapters.cc)

// Reads a PCD file (x, y, z and, when present, normal_x/normal_y/normal_z); NaN points of an
// organized cloud are skipped. Throws Error naming the file on failure.
ScanMesh ReadPcdFile(const std::string& path);

// PCL's StatisticalOutlierRemoval: false for points whose mean distance to their `mean_k` nearest
// neighbours exceeds the global mean by more than `stddev_mul` standard deviations.
std::vector<bool> StatisticalInliers(const std::vector<Eigen::Vector3d>& points, int mean_k, double stddev_mul);

// PCL's NormalEstimation (threads == 1) or NormalEstimationOMP, with neighbours within `radius_m`,
// on coordinates centred on their centroid (PCL stores floats). Unoriented; zero where PCL gives NaN.
std::vector<Eigen::Vector3d> PclNormals(const std::vector<Eigen::Vector3d>& points, double radius_m, int threads);

// --- CGAL (cgal_adapters.cc)

// CGAL's advancing-front surface reconstruction of unorganized points (Cohen-Steiner and Da 2004);
// triangles index into `points`.
std::vector<Eigen::Vector3i> AdvancingFrontReconstruction(const std::vector<Eigen::Vector3d>& points);

struct HullDistances {
  std::vector<double> distance_m;  // per point, distance to the hull's surface (>= 0)
  size_t hull_vertices = 0;
  size_t hull_faces = 0;
  bool valid = false;  // false when the points span no volume (fewer than 4, or coplanar)
};
// The convex hull of the points (CGAL quickhull, on centred coordinates) and each point's distance to
// its surface (an AABB tree over the hull's triangles).
HullDistances ConvexHullDistances(const std::vector<Eigen::Vector3d>& points);

}  // namespace ibrdf::scan_adapters
