#include "align/cylinder_fit.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Geometry>

#include "align/cost_functions/rigid_point_error.h"
#include "core/error.h"

namespace ibrdf {

bool CylinderFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(min_markers, 1);
  IBRDF_CHECK_OPTION_GT(cauchy_m, 0.0);
  IBRDF_CHECK_OPTION_GT(max_marker_rms_m, 0.0);
  return true;
}

std::string CylinderFit::BriefReport() const {
  if (!fitted) return "cylinder as given: " + reason;
  char buffer[320];
  std::snprintf(
      buffer, sizeof(buffer),
      "cylinder centre (%.5f, %.5f, %.5f) m, axis (%.5f, %.5f, %.5f) from %d markers (corner RMS %.3f mm, %d left out)",
      center.x(), center.y(), center.z(), axis.x(), axis.y(), axis.z(), markers, 1e3 * rms_m, rejected_markers);
  return buffer;
}

CylinderFit FitCylinderToMarkers(const SampleTargetsSpec& spec, const std::map<int, BundleMarker>& markers,
                                 const SampleSpec& given, const CylinderFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("cylinder fit options", why);
  CylinderFit fit;
  std::vector<const TargetSpec*> used;
  for (const TargetSpec& target : spec.markers) {
    const auto it = markers.find(target.id);
    if (it != markers.end() && it->second.posed && it->second.images > 0) used.push_back(&target);
  }
  double pose[6] = {0, 0, 0, 0, 0, 0};
  for (int round = 0; round < 2; ++round) {
    if (static_cast<int>(used.size()) < options.min_markers) {
      fit.reason = "only " + std::to_string(used.size()) + " of the sample's markers posed (need " +
                   std::to_string(options.min_markers) + ")";
      fit.fitted = false;
      return fit;
    }
    // The closed-form start (Umeyama, no scale), then the robust refinement.
    Eigen::Matrix3Xd in_sample(3, 4 * used.size()), in_world(3, 4 * used.size());
    for (size_t m = 0; m < used.size(); ++m) {
      for (int c = 0; c < 4; ++c) {
        in_sample.col(4 * m + c) = used[m]->corners[c];
        in_world.col(4 * m + c) = markers.at(used[m]->id).corners[c];
      }
    }
    const Eigen::Matrix4d start = Eigen::umeyama(in_sample, in_world, false);
    AngleAxisFromPose(
        Rigid3d(Eigen::Quaterniond(Eigen::Matrix3d(start.topLeftCorner<3, 3>())), start.topRightCorner<3, 1>()), pose,
        pose + 3);
    ceres::Problem problem;
    for (Eigen::Index k = 0; k < in_sample.cols(); ++k) {
      problem.AddResidualBlock(RigidPointError::Create(in_sample.col(k), in_world.col(k)),
                               new ceres::CauchyLoss(options.cauchy_m), pose, pose + 3);
    }
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.function_tolerance = solver_options.parameter_tolerance = 1e-15;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    if (!summary.IsSolutionUsable()) {
      fit.reason = "the rigid fit failed: " + summary.message;
      return fit;
    }
    fit.world_from_sample = PoseFromAngleAxis(pose, pose + 3);
    // Per marker: its corners' RMS; markers beyond the limit are left out and the fit repeated.
    std::vector<const TargetSpec*> kept;
    double squared = 0.0;
    for (const TargetSpec* target : used) {
      double marker_squared = 0.0;
      for (int c = 0; c < 4; ++c) {
        marker_squared +=
            (fit.world_from_sample * target->corners[c] - markers.at(target->id).corners[c]).squaredNorm();
      }
      if (std::sqrt(marker_squared / 4.0) <= options.max_marker_rms_m) {
        kept.push_back(target);
        squared += marker_squared;
      }
    }
    fit.rejected_markers += static_cast<int>(used.size() - kept.size());
    const bool done = kept.size() == used.size();
    used = kept;
    if (done) {
      fit.markers = static_cast<int>(used.size());
      fit.rms_m = std::sqrt(squared / (4.0 * used.size()));
      break;
    }
    if (round == 1) {
      fit.reason = "the sample's markers disagree (more than " + std::to_string(1e3 * options.max_marker_rms_m) +
                   " mm RMS) after leaving the worst out";
      return fit;
    }
  }
  fit.center = fit.world_from_sample.translation;
  fit.axis = fit.world_from_sample.rotation * Eigen::Vector3d::UnitZ();
  if (fit.axis.dot(given.axis) < 0.0) fit.axis = -fit.axis;
  fit.fitted = true;
  return fit;
}

}  // namespace ibrdf
