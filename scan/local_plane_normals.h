// Local-plane normals (the paper's section 3.1: "the normal is taken from a plane fitted locally to
// the range data", which keeps scanner noise out of the BRDF). For each point, the plane through the
// centroid of the scan points within a radius, by principal component analysis: the normal is the
// eigenvector of the smallest eigenvalue of their covariance, and the fit's RMS residual is the square
// root of that eigenvalue. Coordinates are taken relative to the query point before any sum, so a scan
// far from the origin gives the same normals.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scan/scan_mesh.h"

namespace ibrdf {

struct LocalPlaneOptions {
  // Neighbourhood radius in metres; 0 picks radius_spacing_factor times the point spacing (the median
  // nearest-neighbour distance of a cloud, the median edge length of a mesh).
  double radius_m = 0.0;
  // With radius_m = 0: the radius as a multiple of the median nearest-neighbour distance (3 gathers
  // about 28 points on a regular grid).
  double radius_spacing_factor = 3.0;
  // Fewer neighbours (the point included) than this and no plane is fitted.
  int min_neighbours = 5;
  // A neighbourhood whose middle eigenvalue is below this fraction of the largest is (nearly)
  // collinear: the plane about the line is undefined and no plane is fitted.
  double collinear_ratio = 1e-6;

  bool Check(std::string* why) const;
};

// How a point got its normal.
enum class NormalSource : uint8_t {
  kFitted = 0,     // the local-plane fit
  kReference = 1,  // no fit (too few neighbours, collinear); the mesh's or the file's normal
  kNone = 2,       // no fit and no reference: the normal is zero (never NaN)
};

struct LocalPlaneResult {
  double radius_m = 0.0;                 // the radius used
  double spacing_m = 0.0;                // median point spacing
  std::vector<Eigen::Vector3d> normals;  // unit and outward; zero where source is kNone
  std::vector<float> rms_m;              // RMS distance of the neighbours to the plane (0 without fit)
  std::vector<int> neighbours;           // points in the fit, the point itself included (0 without fit)
  std::vector<NormalSource> source;
  uint64_t points = 0;  // points examined
  uint64_t fitted = 0;
  uint64_t too_few_neighbours = 0;
  uint64_t collinear = 0;
  uint64_t no_normal = 0;  // of the unfitted points, those without a reference normal
  uint64_t flipped = 0;    // fitted normals turned to agree with the outward reference
  double rms_median_m = 0.0, rms_p95_m = 0.0;
  double neighbours_median = 0.0;
  double seconds = 0.0;
  // "normals: 40000 fitted (radius 1.5 mm, median 27 neighbours), RMS residual median 0.08 mm, ..."
  std::string BriefReport() const;
};

// Fits a plane at every point. `reference_normals` (empty, or one per point; zero entries allowed)
// orient the fitted normals: each is turned to agree with its reference, and where no plane can be
// fitted the reference is used. Without one the normal points away from the centroid of the points.
LocalPlaneResult FitLocalPlanes(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Vector3d>& reference_normals,
                                const LocalPlaneOptions& options);

// The same on a mesh, whose point spacing is its median edge length (each scan's own sampling, also
// where merged scans overlap); the references are the normals read from the file when it had them, otherwise
// the area-weighted face normals (outward after OrientFacesOutward).
LocalPlaneResult FitLocalPlanes(const ScanMesh& mesh, const LocalPlaneOptions& options);

// Stores the normals and quality (fit_rms_m, fit_neighbours) in the mesh.
void StoreNormals(const LocalPlaneResult& result, ScanMesh* mesh);

}  // namespace ibrdf
