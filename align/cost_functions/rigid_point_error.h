// A point known in a rigid body's own frame must land on its measured world position: the residual is
// world_from_body * p_in_body - p_in_world (3, metres). Parameters: the body's pose as angle-axis (3)
// and translation (3), world_from_body. Used to place the sample from the markers fixed to it
// (align/cylinder_fit.h).
#pragma once

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Core>

namespace ibrdf {

struct RigidPointError {
  RigidPointError(const Eigen::Vector3d& p_in_body, const Eigen::Vector3d& p_in_world)
      : p_in_body_(p_in_body), p_in_world_(p_in_world) {}

  template <typename T>
  bool operator()(const T* const rotation, const T* const translation, T* residuals) const {
    const T p[3] = {T(p_in_body_.x()), T(p_in_body_.y()), T(p_in_body_.z())};
    T q[3];
    ceres::AngleAxisRotatePoint(rotation, p, q);
    for (int k = 0; k < 3; ++k) residuals[k] = q[k] + translation[k] - p_in_world_[k];
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_in_body, const Eigen::Vector3d& p_in_world) {
    return new ceres::AutoDiffCostFunction<RigidPointError, 3, 3, 3>(new RigidPointError(p_in_body, p_in_world));
  }

 private:
  Eigen::Vector3d p_in_body_, p_in_world_;
};

}  // namespace ibrdf
