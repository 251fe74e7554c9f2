// Rigid transforms and similarities, named target_from_source: p_in_camera = camera_from_world * p_in_world.
#pragma once

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>

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

// A similarity (rotation, translation and a positive scale): x -> scale * rotation * x + translation.
// Brings a scanned mesh into the world frame (`world_from_mesh`): a scanner may work in millimetres
// and far from the world's origin. Normals transform by the rotation alone.
struct Sim3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Sim3d() = default;
  Sim3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t, double s) : rotation(r), translation(t), scale(s) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const { return scale * (rotation * p) + translation; }
  // Composition: (a_from_b * b_from_c) is a_from_c.
  Sim3d operator*(const Sim3d& b_from_c) const {
    return Sim3d(rotation * b_from_c.rotation, scale * (rotation * b_from_c.translation) + translation,
                 scale * b_from_c.scale);
  }
  Sim3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Sim3d(inv, -(inv * translation) / scale, 1.0 / scale);
  }
  bool IsIdentity() const {
    return rotation.coeffs() == Eigen::Quaterniond::Identity().coeffs() && translation.isZero(0.0) && scale == 1.0;
  }
};

// {"rotation": [qw, qx, qy, qz], "translation": [x, y, z], "scale": s} ("scale" left out when 1).
nlohmann::json Sim3dToJson(const Sim3d& sim);
// Reads the form above strictly ("scale" optional, default 1): a quaternion that is not unit length
// (to 1e-6), a scale that is not positive and finite, or an unknown key is an Error naming
// `file` and the JSON `pointer` of the object.
Sim3d Sim3dFromJson(const nlohmann::json& value, const std::string& file, const std::string& pointer);

// The pose of a camera at `center` looking at `target`, with `up` projecting upwards in the image.
// Camera axes as in COLMAP and OpenCV: x right, y down, z forward.
Rigid3d LookAtCameraFromWorld(const Eigen::Vector3d& center, const Eigen::Vector3d& target, const Eigen::Vector3d& up);

}  // namespace ibrdf
