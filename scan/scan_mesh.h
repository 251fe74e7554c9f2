// The sample mesh of the scan stage: scan points in metres, triangles over them, and per-point
// normals with the quality of their local-plane fit.
//
// Decision: the mesh is this plain Eigen struct, not an OpenMesh TriMesh. Every later stage
// (derender intersects rays with it) reads points and triangles, and nothing else; OpenMesh, CGAL and
// PCL are used inside scan/*.cc only (see docs/scan.md). Points are doubles so that a scan far from
// the origin keeps its sub-micrometre detail.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace ibrdf {

// A range image: row-major cells, each holding the index of its point or -1 where the scanner saw
// nothing (the Cyberware `range_grid` element of a PLY file).
struct RangeGrid {
  int rows = 0;
  int cols = 0;
  std::vector<int> cell_point;  // rows * cols entries; point index or -1

  int At(int row, int col) const { return cell_point[static_cast<size_t>(row) * cols + col]; }
  bool Empty() const { return rows == 0 || cols == 0; }
};

struct ScanMesh {
  std::vector<Eigen::Vector3d> points;  // metres
  std::vector<Eigen::Vector3i> faces;   // counter-clockwise seen from outside; indices into points
  // Optional per-point data, each either empty or points.size() long.
  std::vector<Eigen::Vector3d> normals;  // unit, outward (from a file, or the local-plane fit)
  std::vector<float> fit_rms_m;          // RMS distance of the neighbours to the fitted plane
  std::vector<int> fit_neighbours;       // number of points in the fit (0: no fit)
  std::vector<float> hull_distance_m;    // distance to the convex hull of the sample
  RangeGrid grid;                        // set while the mesh is one untessellated range image

  size_t NumPoints() const { return points.size(); }
  size_t NumFaces() const { return faces.size(); }
  // Drops the optional per-point data (after points were reordered or removed).
  void ClearPointData();
};

// Unit normal of a triangle (zero for a degenerate one) and its area (square metres).
Eigen::Vector3d FaceNormal(const ScanMesh& mesh, size_t face);
double FaceArea(const ScanMesh& mesh, size_t face);

// Area-weighted vertex normals from the faces' winding; zero where a point has no (non-degenerate)
// face.
std::vector<Eigen::Vector3d> AreaWeightedVertexNormals(const ScanMesh& mesh);

// A third of the area of every incident face, per point (square metres).
std::vector<double> VertexAreas(const ScanMesh& mesh);

// Keeps the points where keep[i] is true, renumbers the faces, and drops faces that used a removed
// point (their number is returned). Per-point data is filtered alongside.
size_t KeepPoints(const std::vector<bool>& keep, ScanMesh* mesh);

// The mean of the points (zero for none); used to centre coordinates before any fit.
Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points);

// Throws Error naming `where` if any point coordinate is NaN, infinite or beyond 1e6 (metres), or a
// face index is out of range. (Repeated indices within a face are degenerate faces, which cleaning removes and counts.)
void RequireFinitePoints(const ScanMesh& mesh, const std::string& where);

}  // namespace ibrdf
