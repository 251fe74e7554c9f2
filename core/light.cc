#include "core/light.h"

#include <cmath>
#include <limits>

namespace ibrdf {

const char* LightKindName(Light::Kind kind) {
  switch (kind) {
    case Light::Kind::kPoint:
      return "point";
    case Light::Kind::kDirectional:
      return "directional";
  }
  UnhandledKind("Light::Kind", static_cast<int>(kind));
}

const Eigen::Vector3d& LightPlacement(const Light& light) {
  switch (light.kind) {
    case Light::Kind::kPoint:
      return light.position;
    case Light::Kind::kDirectional:
      return light.direction;
  }
  UnhandledKind("Light::Kind", static_cast<int>(light.kind));
}

const char* LightPlacementKey(Light::Kind kind) {
  switch (kind) {
    case Light::Kind::kPoint:
      return "position";
    case Light::Kind::kDirectional:
      return "direction";
  }
  UnhandledKind("Light::Kind", static_cast<int>(kind));
}

Eigen::Vector3d DirectionToLight(const Light& light, const Eigen::Vector3d& point) {
  switch (light.kind) {
    case Light::Kind::kPoint:
      return (light.position - point).normalized();
    case Light::Kind::kDirectional:
      return light.direction.normalized();
  }
  UnhandledKind("Light::Kind", static_cast<int>(light.kind));
}

std::string LightLabel(const Light& light) { return light.id.empty() ? "the light" : "light " + light.id; }

Incidence IncidenceAt(const Light& light, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  Incidence incidence;
  double inverse_square = 1.0;
  switch (light.kind) {
    case Light::Kind::kPoint: {
      const Eigen::Vector3d to_light = light.position - point;
      const double r2 = to_light.squaredNorm();
      if (!(r2 > 0.0) || !std::isfinite(r2)) return incidence;
      incidence.distance = std::sqrt(r2);
      incidence.wi = to_light / incidence.distance;
      inverse_square = 1.0 / r2;
      break;
    }
    case Light::Kind::kDirectional:
      incidence.distance = std::numeric_limits<double>::infinity();
      incidence.wi = light.direction.normalized();
      break;
  }
  incidence.cos_theta = incidence.wi.dot(normal);
  if (!(incidence.cos_theta > 0.0)) return incidence;
  incidence.lit = true;
  incidence.irradiance = light.intensity * (incidence.cos_theta * inverse_square);
  return incidence;
}

}  // namespace ibrdf
