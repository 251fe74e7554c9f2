// A silhouette ray must be tangent to the sphere: the distance from the centre to the ray equals the
// radius. Parameters: centre (3) and radius (1). The ray's origin and unit direction are constants.
#pragma once

#include <ceres/ceres.h>
#include <Eigen/Core>

namespace ibrdf {

struct SphereTangentError {
  SphereTangentError(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction)
      : origin_(origin), direction_(direction.normalized()) {}

  template <typename T>
  bool operator()(const T* const center, const T* const radius, T* residual) const {
    // The component of (centre - origin) perpendicular to the ray.
    T v[3] = {center[0] - origin_.x(), center[1] - origin_.y(), center[2] - origin_.z()};
    const T along = v[0] * direction_.x() + v[1] * direction_.y() + v[2] * direction_.z();
    T perp[3] = {v[0] - along * direction_.x(), v[1] - along * direction_.y(), v[2] - along * direction_.z()};
    const T distance = ceres::sqrt(perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2] + T(1e-30));
    residual[0] = distance - radius[0];
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
    return new ceres::AutoDiffCostFunction<SphereTangentError, 1, 3, 1>(new SphereTangentError(origin, direction));
  }

 private:
  Eigen::Vector3d origin_, direction_;
};

}  // namespace ibrdf
