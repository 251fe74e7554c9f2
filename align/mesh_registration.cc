#include "align/mesh_registration.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"

namespace ibrdf {
namespace {

// One marker seen by both: its corners in the scan frame and in the world.
struct Correspondence {
  int id = -1;
  std::array<Eigen::Vector3d, 4> scan, world;
};

// The similarity (or rigid motion) mapping the scan corners of `pairs[i]` (i in `use`) onto their world
// corners, least squares. Both point sets are centred on their own centroid first, so Umeyama's SVD
// sees coordinates of the size of the layout, not of the scanner's offset.
Sim3d Fit(const std::vector<Correspondence>& pairs, const std::vector<size_t>& use, bool scale) {
  const int n = static_cast<int>(4 * use.size());
  Eigen::Vector3d scan_centre = Eigen::Vector3d::Zero(), world_centre = Eigen::Vector3d::Zero();
  for (size_t i : use) {
    for (int k = 0; k < 4; ++k) {
      scan_centre += pairs[i].scan[k];
      world_centre += pairs[i].world[k];
    }
  }
  scan_centre /= n;
  world_centre /= n;
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  int column = 0;
  for (size_t i : use) {
    for (int k = 0; k < 4; ++k, ++column) {
      src.col(column) = pairs[i].scan[k] - scan_centre;
      dst.col(column) = pairs[i].world[k] - world_centre;
    }
  }
  const Eigen::Matrix4d transform = Eigen::umeyama(src, dst, scale);
  const Eigen::Matrix3d scaled_rotation = transform.topLeftCorner<3, 3>();
  const double s = scale ? std::cbrt(scaled_rotation.determinant()) : 1.0;
  Sim3d sim;
  sim.scale = s;
  sim.rotation = Eigen::Quaterniond(scaled_rotation / s).normalized();
  // p_world = s R (p_scan - scan_centre) + t_centred + world_centre.
  sim.translation = world_centre + transform.topRightCorner<3, 1>() - s * (sim.rotation * scan_centre);
  return sim;
}

double MarkerRms(const Sim3d& world_from_scan, const Correspondence& pair) {
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) sum += (world_from_scan * pair.scan[k] - pair.world[k]).squaredNorm();
  return std::sqrt(sum / 4.0);
}

// The ratio of the second to the first principal extent of the used markers' world centres.
double SpreadRatio(const std::vector<Correspondence>& pairs, const std::vector<size_t>& use) {
  Eigen::Matrix3Xd centres(3, use.size());
  for (size_t j = 0; j < use.size(); ++j) {
    const auto& c = pairs[use[j]].world;
    centres.col(j) = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  }
  const Eigen::Vector3d mean = centres.rowwise().mean();
  centres.colwise() -= mean;
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3Xd>(centres).singularValues();
  return singular[0] > 0.0 ? singular[1] / singular[0] : 0.0;
}

std::string IdList(const std::vector<Correspondence>& pairs, const std::vector<size_t>& use) {
  std::ostringstream out;
  for (size_t j = 0; j < use.size(); ++j) out << (j ? ", " : "") << pairs[use[j]].id;
  return out.str();
}

}  // namespace

bool MeshRegistrationOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(min_markers, 3);
  IBRDF_CHECK_OPTION_GT(max_marker_rms_m, 0.0);
  IBRDF_CHECK_OPTION_GT(min_spread_ratio, 0.0);
  IBRDF_CHECK_OPTION_LT(min_spread_ratio, 1.0);
  IBRDF_CHECK_OPTION_GE(max_outlier_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(max_outlier_fraction, 1.0);
  return true;
}

MeshRegistration RegisterMeshToTargets(const std::vector<ScanTargetSpec>& scan_targets,
                                       const std::vector<TargetSpec>& reference, const MeshRegistrationOptions& options,
                                       const std::string& where) {
  std::string why;
  if (!options.Check(&why)) ThrowError("mesh registration options", why);
  MeshRegistration result;
  std::map<int, const TargetSpec*> layout;
  for (const TargetSpec& target : reference) layout[target.id] = &target;
  std::vector<Correspondence> pairs;
  std::map<int, int> seen;
  for (const ScanTargetSpec& target : scan_targets) {
    if (seen[target.id]++ > 0) ThrowError(where, "marker id " + std::to_string(target.id) + " is listed twice");
    const auto found = layout.find(target.id);
    if (found == layout.end()) {
      result.unmatched_ids.push_back(target.id);
      continue;
    }
    Correspondence pair;
    pair.id = target.id;
    pair.scan = target.corners;
    pair.world = found->second->corners;
    pairs.push_back(pair);
  }
  if (static_cast<int>(pairs.size()) < options.min_markers) {
    ThrowError(where, "only " + std::to_string(pairs.size()) +
                          " marker(s) shared with targets.reference; registering " + "the mesh needs at least " +
                          std::to_string(options.min_markers) + " markers the scanner and the layout share");
  }
  std::vector<size_t> use(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) use[i] = i;
  result.markers.resize(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) result.markers[i].id = pairs[i].id;
  auto check_layout = [&](const std::vector<size_t>& set) {
    const double ratio = SpreadRatio(pairs, set);
    if (ratio < options.min_spread_ratio) {
      std::ostringstream message;
      message << "the markers used (" << IdList(pairs, set) << ") lie nearly on a line (spread ratio " << ratio
              << ", need " << options.min_spread_ratio << "): the rotation about that line is undetermined";
      ThrowError(where, message.str());
    }
  };
  check_layout(use);
  Sim3d sim = Fit(pairs, use, options.estimate_scale);
  while (true) {
    double worst = 0.0;
    for (size_t i : use) worst = std::max(worst, MarkerRms(sim, pairs[i]));
    if (worst <= options.max_marker_rms_m) break;
    // Leave-one-out: each used marker's residual under the fit without it; the worst is dropped.
    const size_t max_outliers = std::max<size_t>(1, static_cast<size_t>(options.max_outlier_fraction * pairs.size()));
    if (static_cast<int>(use.size()) <= options.min_markers || pairs.size() - use.size() >= max_outliers) {
      std::ostringstream message;
      message << "marker corners miss their layout by up to " << worst * 1e3 << " mm RMS (threshold "
              << options.max_marker_rms_m * 1e3 << " mm) with " << pairs.size() - use.size() << " of " << pairs.size()
              << " markers dropped already (" << use.size() << " left, at least " << options.min_markers
              << " needed, at most " << max_outliers << " outliers): the scan targets do not match targets.reference";
      ThrowError(where, message.str());
    }
    size_t drop = use.size();
    double drop_residual = -1.0;
    for (size_t j = 0; j < use.size(); ++j) {
      std::vector<size_t> others = use;
      others.erase(others.begin() + j);
      if (SpreadRatio(pairs, others) < options.min_spread_ratio) continue;
      const double residual = MarkerRms(Fit(pairs, others, options.estimate_scale), pairs[use[j]]);
      result.markers[use[j]].leave_one_out_m = residual;
      if (residual > drop_residual) {
        drop_residual = residual;
        drop = j;
      }
    }
    if (drop == use.size() || drop_residual <= options.max_marker_rms_m) {
      std::ostringstream message;
      message << "marker corners miss their layout by up to " << worst * 1e3 << " mm RMS (threshold "
              << options.max_marker_rms_m * 1e3 << " mm), and leaving out any one marker does not explain it: the "
              << "scan targets do not match targets.reference (wrong ids, or a scale the fit cannot take)";
      ThrowError(where, message.str());
    }
    std::ostringstream reason;
    reason << "outlier: " << drop_residual * 1e3 << " mm RMS from the fit without it";
    result.markers[use[drop]].dropped_reason = reason.str();
    use.erase(use.begin() + drop);
    check_layout(use);
    sim = Fit(pairs, use, options.estimate_scale);
  }
  double sum = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    result.markers[i].rms_m = MarkerRms(sim, pairs[i]);
    result.markers[i].used = std::find(use.begin(), use.end(), i) != use.end();
    if (result.markers[i].used) {
      sum += result.markers[i].rms_m * result.markers[i].rms_m;
      result.max_marker_rms_m = std::max(result.max_marker_rms_m, result.markers[i].rms_m);
    }
  }
  result.used_markers = static_cast<int>(use.size());
  result.rms_m = std::sqrt(sum / use.size());
  result.world_from_mesh = sim;
  return result;
}

std::string MeshRegistration::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "mesh registration: %d of %zu markers, corner RMS %.3f mm (worst marker %.3f mm), scale %.6f",
                used_markers, markers.size(), rms_m * 1e3, max_marker_rms_m * 1e3, world_from_mesh.scale);
  std::string report = buffer;
  for (const MarkerRegistrationResidual& marker : markers) {
    if (!marker.used) report += "; dropped marker " + std::to_string(marker.id) + " (" + marker.dropped_reason + ")";
  }
  if (!unmatched_ids.empty())
    report += "; " + std::to_string(unmatched_ids.size()) + " scan target(s) not in the layout";
  return report;
}

nlohmann::json ToJson(const MeshRegistration& registration) {
  nlohmann::json markers = nlohmann::json::array();
  for (const MarkerRegistrationResidual& marker : registration.markers) {
    nlohmann::json entry = {{"id", marker.id}, {"used", marker.used}, {"rms_m", marker.rms_m}};
    if (marker.leave_one_out_m >= 0.0) entry["leave_one_out_rms_m"] = marker.leave_one_out_m;
    if (!marker.used) entry["dropped"] = marker.dropped_reason;
    markers.push_back(entry);
  }
  return {{"world_from_mesh", Sim3dToJson(registration.world_from_mesh)},
          {"used_markers", registration.used_markers},
          {"rms_m", registration.rms_m},
          {"max_marker_rms_m", registration.max_marker_rms_m},
          {"markers", markers},
          {"unmatched_ids", registration.unmatched_ids}};
}

}  // namespace ibrdf
