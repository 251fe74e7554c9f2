// Reprojection error of a corner of a marker whose pose is unknown (a marker on the light): the corner
// is fixed in the marker's own frame and reaches the world through the marker's pose. Parameters: the
// camera's pose as angle-axis (3) and translation (3), camera_from_world; the marker's pose as
// angle-axis (3) and translation (3), world_from_marker. The corner in the marker frame, the observed
// pixel and the intrinsics (as in reprojection_error.h) are constants.
#pragma once

#include <array>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Core>

#include "align/cost_functions/reprojection_error.h"

namespace ibrdf {

struct MarkerCornerError {
  MarkerCornerError(const std::array<double, 8>& intrinsics, const Eigen::Vector3d& corner_in_marker, double observed_x,
                    double observed_y)
      : projection_(intrinsics, observed_x, observed_y), corner_in_marker_(corner_in_marker) {}

  template <typename T>
  bool operator()(const T* const camera_rotation, const T* const camera_translation, const T* const marker_rotation,
                  const T* const marker_translation, T* residuals) const {
    const T corner[3] = {T(corner_in_marker_.x()), T(corner_in_marker_.y()), T(corner_in_marker_.z())};
    T p_in_world[3];
    ceres::AngleAxisRotatePoint(marker_rotation, corner, p_in_world);
    for (int k = 0; k < 3; ++k) p_in_world[k] += marker_translation[k];
    return projection_(camera_rotation, camera_translation, p_in_world, residuals);
  }

  static ceres::CostFunction* Create(const std::array<double, 8>& intrinsics, const Eigen::Vector3d& corner_in_marker,
                                     double observed_x, double observed_y) {
    return new ceres::AutoDiffCostFunction<MarkerCornerError, 2, 3, 3, 3, 3>(
        new MarkerCornerError(intrinsics, corner_in_marker, observed_x, observed_y));
  }

 private:
  ReprojectionError projection_;
  Eigen::Vector3d corner_in_marker_;
};

}  // namespace ibrdf
