// The convexity report: how far the sample departs from its convex hull. The paper measures convex
// samples because on them no point shadows or lights another; where the surface lies well inside the
// hull, self-shadowing and interreflection can bias the measurement, and the derenderer must trace
// shadow rays there (the derender issue reads `needs_shadow_rays`).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "scan/scan_mesh.h"

namespace ibrdf {

struct ConvexityOptions {
  // A point within this distance of the hull counts as on it (metres); 0 picks tolerance_fraction of
  // the bounding-box diagonal.
  double tolerance_m = 0.0;
  // With tolerance_m = 0: the tolerance as a fraction of the bounding-box diagonal (0.005: 0.9 mm on
  // a 100 mm cube's diagonal of 173 mm).
  double tolerance_fraction = 0.005;
  // The sample counts as convex when at least this fraction of its surface (by area) lies within the
  // tolerance of the hull; otherwise shadow rays are needed.
  double min_convex_fraction = 0.99;

  bool Check(std::string* why) const;
};

struct ConvexityReport {
  bool flat = false;  // the points span no volume (coplanar): trivially convex
  size_t hull_vertices = 0, hull_faces = 0;
  double tolerance_m = 0.0;
  double fraction_within = 0.0;  // of the surface area (of the points when there are no faces)
  double max_distance_m = 0.0;
  double median_distance_m = 0.0;
  bool needs_shadow_rays = true;   // fraction_within < min_convex_fraction (true until the report ran)
  std::string warning;             // empty when convex
  std::vector<double> distance_m;  // per point, to the hull's surface
  // "convexity: 99.8 % of the surface within 0.87 mm of the convex hull (max 0.3 mm): convex"
  std::string BriefReport() const;
  nlohmann::json ToJson() const;  // the figures, without the per-point distances
};

// Builds the convex hull of the mesh's points (CGAL) and measures each point's distance to it.
// Throws Error for fewer than 4 points.
ConvexityReport ReportConvexity(const ScanMesh& mesh, const ConvexityOptions& options);

}  // namespace ibrdf
