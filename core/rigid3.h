// Rigid transforms, named target_from_source: p_in_camera = camera_from_world * p_in_world.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ibrdf {

// A rotation followed by a translation (COLMAP's Rigid3d): x -> rotation * x + translation.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t) : rotation(r), translation(t) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return rotation * p + translation; }
  // Composition: (a_from_b * b_from_c) is a_from_c.
  Rigid3d operator*(const Rigid3d& b_from_c) const {
    return Rigid3d(rotation * b_from_c.rotation, rotation * b_from_c.translation + translation);
  }
  // For camera_from_world this is world_from_camera.
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3d(inv, -(inv * translation));
  }
  Eigen::Matrix<double, 3, 4> ToMatrix() const {
    Eigen::Matrix<double, 3, 4> m;
    m.leftCols<3>() = rotation.toRotationMatrix();
    m.col(3) = translation;
    return m;
  }
};

// The pose of a camera at `center` looking at `target`, with `up` projecting upwards in the image.
// Camera axes as in COLMAP and OpenCV: x right, y down, z forward.
Rigid3d LookAtCameraFromWorld(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                              const Eigen::Vector3d& up);

}  // namespace ibrdf
