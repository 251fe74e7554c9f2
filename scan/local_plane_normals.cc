#include "scan/local_plane_normals.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "scan/point_index.h"

namespace ibrdf {

bool LocalPlaneOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(radius_m, 0.0);  // 0: from the point spacing
  IBRDF_CHECK_OPTION(std::isfinite(radius_m));
  IBRDF_CHECK_OPTION_GT(radius_spacing_factor, 0.0);
  IBRDF_CHECK_OPTION_GE(min_neighbours, 3);  // a plane needs three points
  IBRDF_CHECK_OPTION_GT(collinear_ratio, 0.0);
  IBRDF_CHECK_OPTION_LT(collinear_ratio, 1.0);
  return true;
}

std::string LocalPlaneResult::BriefReport() const {
  std::ostringstream out;
  out.precision(3);
  out << "normals: " << fitted << " of " << points << " fitted (radius " << radius_m * 1e3 << " mm, median "
      << neighbours_median << " neighbours), RMS residual median " << rms_median_m * 1e3 << " mm, 95th percentile "
      << rms_p95_m * 1e3 << " mm; not fitted: too_few_neighbours " << too_few_neighbours << ", collinear " << collinear
      << " (" << no_normal << " left without a normal)";
  return out.str();
}

namespace {
LocalPlaneResult Fit(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& reference_normals,
                     const LocalPlaneOptions& options, double spacing_m) {
  std::string why;
  if (!options.Check(&why)) ThrowError("local-plane options", why);
  IBRDF_CHECK(reference_normals.empty() || reference_normals.size() == points.size())
      << reference_normals.size() << " reference normals for " << points.size() << " points";
  const Timer timer;
  LocalPlaneResult result;
  const size_t n = points.size();
  result.normals.assign(n, Eigen::Vector3d::Zero());
  result.rms_m.assign(n, 0.0f);
  result.neighbours.assign(n, 0);
  result.source.assign(n, NormalSource::kNone);
  result.points = n;
  result.spacing_m = spacing_m;
  result.radius_m = options.radius_m > 0.0 ? options.radius_m : options.radius_spacing_factor * result.spacing_m;
  if (n == 0) return result;
  const Eigen::Vector3d centre = Centroid(points);
  const PointIndex index(points);
  std::vector<uint8_t> flipped(n, 0), collinear(n, 0);
  ProgressBar progress("local planes", n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<int> near;
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const Eigen::Vector3d& q = points[i];
      Eigen::Vector3d reference = reference_normals.empty() ? Eigen::Vector3d::Zero() : reference_normals[i];
      const bool have_reference = reference.allFinite() && reference.squaredNorm() > 0.0;
      if (!have_reference) reference = Eigen::Vector3d::Zero();
      if (result.radius_m > 0.0)
        index.RadiusSearch(q, result.radius_m, &near);
      else
        near.assign(1, static_cast<int>(i));
      bool fitted = false;
      if (static_cast<int>(near.size()) >= options.min_neighbours) {
        // Offsets from the query point: small numbers wherever the scan lies.
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (int j : near) mean += points[j] - q;
        mean /= static_cast<double>(near.size());
        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
        for (int j : near) {
          const Eigen::Vector3d d = points[j] - q - mean;
          covariance.noalias() += d * d.transpose();
        }
        covariance /= static_cast<double>(near.size());
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
        const Eigen::Vector3d eigenvalues = solver.eigenvalues();  // ascending
        if (solver.info() == Eigen::Success && eigenvalues[2] > 0.0 &&
            eigenvalues[1] > options.collinear_ratio * eigenvalues[2]) {
          Eigen::Vector3d normal = solver.eigenvectors().col(0).normalized();
          const Eigen::Vector3d outward = have_reference ? reference : Eigen::Vector3d(q - centre);
          if (normal.dot(outward) < 0.0) {
            normal = -normal;
            flipped[i] = 1;
          }
          result.normals[i] = normal;
          result.rms_m[i] = static_cast<float>(std::sqrt(std::max(0.0, eigenvalues[0])));
          result.neighbours[i] = static_cast<int>(near.size());
          result.source[i] = NormalSource::kFitted;
          fitted = true;
        } else {
          collinear[i] = 1;
        }
      }
      if (!fitted && have_reference) {
        result.normals[i] = reference.normalized();
        result.source[i] = NormalSource::kReference;
      }
    }
    progress.Add(range.size());
  });
  progress.Finish();
  std::vector<float> rms;
  std::vector<int> counts;
  for (size_t i = 0; i < n; ++i) {
    if (result.source[i] == NormalSource::kFitted) {
      ++result.fitted;
      rms.push_back(result.rms_m[i]);
      counts.push_back(result.neighbours[i]);
    } else if (collinear[i]) {
      ++result.collinear;
    } else {
      ++result.too_few_neighbours;
    }
    result.no_normal += result.source[i] == NormalSource::kNone;
    result.flipped += flipped[i];
  }
  if (!rms.empty()) {
    std::sort(rms.begin(), rms.end());
    std::sort(counts.begin(), counts.end());
    result.rms_median_m = rms[rms.size() / 2];
    result.rms_p95_m = rms[std::min(rms.size() - 1, static_cast<size_t>(0.95 * rms.size()))];
    result.neighbours_median = counts[counts.size() / 2];
  }
  result.seconds = timer.ElapsedSeconds();
  return result;
}

}  // namespace

LocalPlaneResult FitLocalPlanes(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Vector3d>& reference_normals,
                                const LocalPlaneOptions& options) {
  return Fit(points, reference_normals, options, MedianPointSpacing(points));
}

LocalPlaneResult FitLocalPlanes(const ScanMesh& mesh, const LocalPlaneOptions& options) {
  // The spacing of a mesh is its median edge length: each scan's own sampling, where the nearest
  // point of a merged cloud may come from an overlapping scan and understate it.
  double spacing = 0.0;
  if (!mesh.faces.empty()) {
    std::vector<double> edges;
    const size_t step = std::max<size_t>(1, mesh.faces.size() / 20000);
    for (size_t i = 0; i < mesh.faces.size(); i += step) {
      const Eigen::Vector3i& f = mesh.faces[i];
      for (int k = 0; k < 3; ++k) edges.push_back((mesh.points[f[k]] - mesh.points[f[(k + 1) % 3]]).norm());
    }
    spacing = PercentileInPlace(&edges, 0.5);
  } else {
    spacing = MedianPointSpacing(mesh.points);
  }
  if (mesh.normals.size() == mesh.points.size() && !mesh.points.empty()) {
    return Fit(mesh.points, mesh.normals, options, spacing);
  }
  return Fit(mesh.points, AreaWeightedVertexNormals(mesh), options, spacing);
}

void StoreNormals(const LocalPlaneResult& result, ScanMesh* mesh) {
  IBRDF_CHECK(result.normals.size() == mesh->points.size()) << "normals of another mesh";
  mesh->normals = result.normals;
  mesh->fit_rms_m = result.rms_m;
  mesh->fit_neighbours = result.neighbours;
}

}  // namespace ibrdf
