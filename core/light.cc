#include "core/light.h"

#include <cmath>
#include <limits>

namespace ibrdf {

const char* LightKindName(Light::Kind kind) { return kind == Light::Kind::kPoint ? "point" : "directional"; }

std::string LightLabel(const Light& light) { return light.id.empty() ? "the light" : "light " + light.id; }

Incidence IncidenceAt(const Light& light, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  Incidence incidence;
  double inverse_square = 1.0;
  if (light.kind == Light::Kind::kPoint) {
    const Eigen::Vector3d to_light = light.position - point;
    const double r2 = to_light.squaredNorm();
    if (!(r2 > 0.0) || !std::isfinite(r2)) return incidence;
    incidence.distance = std::sqrt(r2);
    incidence.wi = to_light / incidence.distance;
    inverse_square = 1.0 / r2;
  } else {
    incidence.distance = std::numeric_limits<double>::infinity();
    incidence.wi = light.direction.normalized();
  }
  incidence.cos_theta = incidence.wi.dot(normal);
  if (!(incidence.cos_theta > 0.0)) return incidence;
  incidence.lit = true;
  incidence.irradiance = light.intensity * (incidence.cos_theta * inverse_square);
  return incidence;
}

}  // namespace ibrdf
