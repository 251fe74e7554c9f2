// Reprojection error of a 3D point in a camera with COLMAP-convention intrinsics, for Ceres.
// Parameters: the camera's pose as angle-axis (3) and translation (3), camera_from_world; the point
// in the world (3). Intrinsics are constants: fx, fy, cx, cy and OpenCV's k1, k2, p1, p2 (zero for the
// models without them), so every supported camera model reduces to this one form.
#pragma once

#include <array>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

namespace ibrdf {

struct ReprojectionError {
  ReprojectionError(const std::array<double, 8>& intrinsics, double observed_x, double observed_y)
      : intrinsics_(intrinsics), observed_x_(observed_x), observed_y_(observed_y) {}

  template <typename T>
  bool operator()(const T* const rotation, const T* const translation, const T* const point, T* residuals) const {
    T p[3];
    ceres::AngleAxisRotatePoint(rotation, point, p);
    p[0] += translation[0];
    p[1] += translation[1];
    p[2] += translation[2];
    const T x = p[0] / p[2], y = p[1] / p[2];
    const double k1 = intrinsics_[4], k2 = intrinsics_[5], p1 = intrinsics_[6], p2 = intrinsics_[7];
    const T r2 = x * x + y * y;
    const T radial = T(1.0) + k1 * r2 + k2 * r2 * r2;
    const T xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
    const T yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
    residuals[0] = intrinsics_[0] * xd + intrinsics_[2] - observed_x_;
    residuals[1] = intrinsics_[1] * yd + intrinsics_[3] - observed_y_;
    return true;
  }

  static ceres::CostFunction* Create(const std::array<double, 8>& intrinsics, double observed_x, double observed_y) {
    return new ceres::AutoDiffCostFunction<ReprojectionError, 2, 3, 3, 3>(
        new ReprojectionError(intrinsics, observed_x, observed_y));
  }

 private:
  std::array<double, 8> intrinsics_;
  double observed_x_, observed_y_;
};

}  // namespace ibrdf
