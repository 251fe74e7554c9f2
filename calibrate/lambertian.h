// The light's intensity from a Lambertian reference of known albedo (a white reference, a diffuse
// sphere): it reflects radiance L = rho / pi * E, with E = I e and e the irradiance per unit of
// intensity (Incidence::irradiance of the light at intensity 1, core/light.h: cos(theta_i) / r^2 for a
// point light, cos(theta_i) for a directional one), so I = pi L / (rho e), i.e. pi L r^2 / (rho
// cos(theta_i)) for a point light. The one formula of both intensity calibrations.
#pragma once

namespace ibrdf {

inline double LambertianIntensity(double radiance, double rho, double unit_irradiance) {
  return 3.14159265358979323846 * radiance / (rho * unit_irradiance);
}

}  // namespace ibrdf
