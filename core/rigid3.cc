#include "core/rigid3.h"

#include "core/error.h"

namespace ibrdf {

Rigid3d LookAtCameraFromWorld(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                              const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - center).normalized();
  Eigen::Vector3d x = z.cross(up);
  IBRDF_CHECK(x.norm() > 1e-12) << "look-at direction is parallel to up";
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);  // points down in the image
  Eigen::Matrix3d camera_from_world_rotation;
  camera_from_world_rotation.row(0) = x;
  camera_from_world_rotation.row(1) = y;
  camera_from_world_rotation.row(2) = z;
  const Eigen::Quaterniond rotation(camera_from_world_rotation);
  return Rigid3d(rotation, -(rotation * center));
}

}  // namespace ibrdf
