#include "core/rigid3.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"

namespace ibrdf {

Rigid3d LookAtCameraFromWorld(const Eigen::Vector3d& center, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
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

nlohmann::json Sim3dToJson(const Sim3d& sim) {
  const Eigen::Quaterniond& q = sim.rotation;
  nlohmann::json json = {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", ToJson(sim.translation)}};
  if (sim.scale != 1.0) json["scale"] = sim.scale;
  return json;
}

Sim3d Sim3dFromJson(const nlohmann::json& value, const std::string& file, const std::string& pointer) {
  if (!value.is_object()) {
    ThrowError(file + ": " + pointer,
               "expected an object {\"rotation\", \"translation\", \"scale\"}, got " + JsonTypeName(value));
  }
  JsonObject object(value, file, pointer);
  const std::vector<double> q = object.Numbers("rotation");
  if (q.size() != 4) ThrowError(object.Where("rotation"), "expected a quaternion [qw, qx, qy, qz]");
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= 1e-6)) {
    ThrowError(object.Where("rotation"), "quaternion is not unit length (norm " + std::to_string(norm) + ")");
  }
  Sim3d sim;
  sim.rotation = Eigen::Quaterniond(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  sim.translation = object.Vector3("translation");
  if (!sim.translation.allFinite()) ThrowError(object.Where("translation"), "expected finite numbers");
  sim.scale = object.Number("scale", 1.0);
  if (!(sim.scale > 0.0) || !std::isfinite(sim.scale)) {
    ThrowError(object.Where("scale"), "must be positive and finite, got " + std::to_string(sim.scale));
  }
  object.Finish();
  return sim;
}

}  // namespace ibrdf
