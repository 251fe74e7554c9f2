#include "scan/convexity.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "scan/adapters.h"

namespace ibrdf {

bool ConvexityOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(tolerance_m, 0.0);  // 0: a fraction of the size
  IBRDF_CHECK_OPTION(std::isfinite(tolerance_m));
  IBRDF_CHECK_OPTION_GT(tolerance_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(tolerance_fraction, 1.0);
  IBRDF_CHECK_OPTION_GT(min_convex_fraction, 0.0);
  IBRDF_CHECK_OPTION_LE(min_convex_fraction, 1.0);
  return true;
}

std::string ConvexityReport::BriefReport() const {
  std::ostringstream out;
  out.precision(4);
  out << "convexity: " << 100.0 * fraction_within << " % of the surface within " << tolerance_m * 1e3
      << " mm of the convex hull (median " << median_distance_m * 1e3 << " mm, max " << max_distance_m * 1e3
      << " mm): " << (flat ? "flat, " : "") << (needs_shadow_rays ? "NOT convex, shadow rays needed" : "convex");
  return out.str();
}

nlohmann::json ConvexityReport::ToJson() const {
  return {{"flat", flat},
          {"hull_vertices", hull_vertices},
          {"hull_faces", hull_faces},
          {"tolerance_m", tolerance_m},
          {"fraction_within_tolerance", fraction_within},
          {"median_distance_m", median_distance_m},
          {"max_distance_m", max_distance_m},
          {"needs_shadow_rays", needs_shadow_rays},
          {"warning", warning}};
}

ConvexityReport ReportConvexity(const ScanMesh& mesh, const ConvexityOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("convexity options", why);
  if (mesh.points.size() < 4) {
    ThrowError("convexity",
               "a convex hull needs at least 4 points, the sample has " + std::to_string(mesh.points.size()));
  }
  ConvexityReport report;
  const size_t n = mesh.points.size();
  Eigen::Vector3d low = mesh.points[0], high = mesh.points[0];
  for (const Eigen::Vector3d& p : mesh.points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const double diagonal = (high - low).norm();
  report.tolerance_m = options.tolerance_m > 0.0 ? options.tolerance_m : options.tolerance_fraction * diagonal;

  // Flat (coplanar) points span no volume: every point lies on the boundary of its hull.
  const Eigen::Vector3d centre = Centroid(mesh.points);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : mesh.points) covariance += (p - centre) * (p - centre).transpose();
  covariance /= static_cast<double>(n);
  const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues();
  const scan_adapters::HullDistances hull = std::sqrt(std::max(0.0, eigenvalues[0])) <= 1e-9 * diagonal
                                                ? scan_adapters::HullDistances()
                                                : scan_adapters::ConvexHullDistances(mesh.points);
  if (!hull.valid) {
    report.flat = true;
    report.distance_m.assign(n, 0.0);
  } else {
    report.distance_m = hull.distance_m;
    report.hull_vertices = hull.hull_vertices;
    report.hull_faces = hull.hull_faces;
  }
  std::vector<double> weights = mesh.faces.empty() ? std::vector<double>(n, 1.0) : VertexAreas(mesh);
  double total = 0.0, within = 0.0;
  for (size_t i = 0; i < n; ++i) {
    total += weights[i];
    if (report.distance_m[i] <= report.tolerance_m) within += weights[i];
  }
  report.fraction_within = total > 0.0 ? within / total : 1.0;
  std::vector<double> sorted = report.distance_m;
  std::sort(sorted.begin(), sorted.end());
  report.median_distance_m = sorted[n / 2];
  report.max_distance_m = sorted.back();
  report.needs_shadow_rays = report.fraction_within < options.min_convex_fraction;
  if (report.needs_shadow_rays) {
    std::ostringstream warning;
    warning.precision(3);
    warning << 100.0 * (1.0 - report.fraction_within) << " % of the surface lies more than " << report.tolerance_m * 1e3
            << " mm inside the convex hull (up to " << report.max_distance_m * 1e3
            << " mm): self-shadowing and interreflection can bias the measurement there; derender must trace "
               "shadow rays";
    report.warning = warning.str();
  }
  return report;
}

}  // namespace ibrdf
