#include "core/brdf_coords.h"

#include <cmath>

namespace ibrdf {

LocalFrame LocalFrame::FromNormal(const Eigen::Vector3d& n) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double b = n.x() * n.y() * a;
  LocalFrame frame;
  frame.n = n;
  frame.s = Eigen::Vector3d(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
  frame.t = Eigen::Vector3d(b, sign + n.y() * n.y() * a, -n.y());
  return frame;
}

// sqrt(x^2 + y^2) rather than hypot: directions are unit length, so nothing overflows, and glibc's
// correctly rounded hypot costs several times more.
double PolarAngle(const Eigen::Vector3d& w) { return std::atan2(std::sqrt(w.x() * w.x() + w.y() * w.y()), w.z()); }

double Azimuth(const Eigen::Vector3d& w) {
  if (w.x() == 0.0 && w.y() == 0.0) return 0.0;
  return WrapAngle(std::atan2(w.y(), w.x()));
}

Eigen::Vector3d FromSpherical(double theta, double phi) {
  const double sin_theta = std::sin(theta);
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::cos(theta)};
}

double WrapAngle(double angle) {
  if (angle > -M_PI && angle <= M_PI) return angle;
  angle = std::remainder(angle, 2.0 * M_PI);  // in [-pi, pi]
  return angle <= -M_PI ? angle + 2.0 * M_PI : angle;
}

BrdfAngles ToBrdfAngles(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  return {PolarAngle(wi), Azimuth(wi), PolarAngle(wo), Azimuth(wo)};
}

void FromBrdfAngles(const BrdfAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo) {
  *wi = FromSpherical(angles.theta_i, angles.phi_i);
  *wo = FromSpherical(angles.theta_e, angles.phi_e);
}

IsotropicAngles ToIsotropic(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  // delta_phi from the in-plane parts directly: atan2(cross, dot) needs no azimuth of either vector.
  const double cross = wi.x() * wo.y() - wi.y() * wo.x();
  const double dot = wi.x() * wo.x() + wi.y() * wo.y();
  IsotropicAngles angles;
  angles.theta_i = PolarAngle(wi);
  angles.theta_e = PolarAngle(wo);
  if (cross == 0.0 && dot == 0.0) {
    // One direction is the normal: delta_phi is the other's azimuth (the BRDF cannot depend on it).
    angles.delta_phi = (wi.x() == 0.0 && wi.y() == 0.0) ? Azimuth(wo) : -Azimuth(wi);
  } else {
    angles.delta_phi = WrapAngle(std::atan2(cross, dot));
  }
  return angles;
}

void FromIsotropic(const IsotropicAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo) {
  *wi = FromSpherical(angles.theta_i, 0.0);
  *wo = FromSpherical(angles.theta_e, angles.delta_phi);
}

namespace {
// Rotates v about z by angle (right-handed).
Eigen::Vector3d RotateZ(const Eigen::Vector3d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}
// Rotates v about y by angle (right-handed).
Eigen::Vector3d RotateY(const Eigen::Vector3d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z()};
}
}  // namespace

bool ToHalfDiff(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, HalfDiffAngles* angles) {
  const Eigen::Vector3d sum = wi + wo;
  const double norm = sum.norm();
  if (!(norm > 1e-12)) {
    *angles = HalfDiffAngles();
    return false;
  }
  const Eigen::Vector3d h = sum / norm;
  angles->theta_h = PolarAngle(h);
  angles->phi_h = Azimuth(h);
  const Eigen::Vector3d d = RotateY(RotateZ(wi, -angles->phi_h), -angles->theta_h);
  angles->theta_d = PolarAngle(d);
  angles->phi_d = Azimuth(d);
  return true;
}

void FromHalfDiff(const HalfDiffAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo) {
  const Eigen::Vector3d h = FromSpherical(angles.theta_h, angles.phi_h);
  const Eigen::Vector3d d = FromSpherical(angles.theta_d, angles.phi_d);
  *wi = RotateZ(RotateY(d, angles.theta_h), angles.phi_h);
  *wo = 2.0 * wi->dot(h) * h - *wi;
}

}  // namespace ibrdf
