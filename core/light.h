// The one small light of an image-based BRDF measurement (the paper's section 3).
#pragma once

#include <string>

#include <Eigen/Core>

#include "core/kind.h"

namespace ibrdf {

struct Light {
  // The light's name in the session (docs/session-format.md, version 2: photos name their light by
  // it); empty for the one light of a session that states a single `light`.
  std::string id;
  enum class Kind {
    kPoint,        // a small source at `position`; `intensity` is radiant intensity (per steradian)
    kDirectional,  // a distant source towards `direction`; `intensity` is irradiance at normal incidence
    IBRDF_DUMMY_KIND
  };
  Kind kind = Kind::kPoint;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    // metres, world frame (point light)
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, towards the light (directional)
  // RGB, in the session's radiance units (linear pixel value per second of exposure at unit gain)
  // times square metres for a point light.
  Eigen::Vector3d intensity = Eigen::Vector3d::Ones();
  // False where the session states no intensity for this light: a calibration (the white reference,
  // calibrate/white_reference_intensity.h) must measure it before the light is used; `intensity` is then a
  // placeholder (ones).
  bool has_intensity = true;
  // False where the session states the placement as "unknown": a light on the targets' light card,
  // whose position `ibrdf align` finds from its markers. `position` (or `direction`) is then a
  // placeholder that no stage may use: align fails when it cannot find the light, derender refuses it.
  bool placement_known = true;
};

// "point", "directional": the kind's name in the session format.
const char* LightKindName(Light::Kind kind);
// The vector that places the light: its position (point light) or its direction (directional light).
const Eigen::Vector3d& LightPlacement(const Light& light);
// That vector's key in the session format: "position" or "direction".
const char* LightPlacementKey(Light::Kind kind);
// The unit direction from `point` towards the light (the light's direction, normalized, for a
// directional light).
Eigen::Vector3d DirectionToLight(const Light& light, const Eigen::Vector3d& point);
// The light's name for messages: "light L07", or "the light" for an unnamed one.
std::string LightLabel(const Light& light);

// What a surface point receives from the light.
struct Incidence {
  Eigen::Vector3d wi = Eigen::Vector3d::Zero();          // unit direction towards the light, world frame
  double cos_theta = 0.0;                                // wi . normal; <= 0 means the light is behind
  double distance = 0.0;                                 // metres to a point light; +inf if directional
  Eigen::Vector3d irradiance = Eigen::Vector3d::Zero();  // E = I cos(theta_i) / r^2, RGB; 0 if unlit
  bool lit = false;                                      // cos_theta > 0 and a finite distance
};

// The irradiance at `point` with unit `normal`, E = I cos(theta_i) / r^2 for a point light.
// A point coinciding with the light, or a light behind the surface, gives lit = false.
Incidence IncidenceAt(const Light& light, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

}  // namespace ibrdf
