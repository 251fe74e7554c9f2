// BRDF coordinates: the local shading frame, spherical angles, the isotropic (theta_i, theta_e,
// delta_phi) form, and Rusinkiewicz's half/difference angles (Rusinkiewicz 1998; the MERL layout).
//
// Directions wi (towards the light) and wo (towards the camera) are unit vectors; in the local frame z
// is the surface normal. Angles are radians. Polar angles come from atan2(sin, cos), which is accurate
// both at theta = 0 and at grazing, where acos loses half its digits. Where an azimuth is undefined
// (a direction along the normal) it is 0, which every isotropic BRDF is free to assume.
#pragma once

#include <Eigen/Core>

namespace ibrdf {

// An orthonormal right-handed frame (s, t, n) around a unit normal n.
struct LocalFrame {
  Eigen::Vector3d s, t, n;

  // A continuous frame from any unit normal (Duff et al. 2017, "Building an orthonormal basis,
  // revisited"): no branch on a reference axis, well conditioned for every n.
  static LocalFrame FromNormal(const Eigen::Vector3d& n);

  Eigen::Vector3d ToLocal(const Eigen::Vector3d& v) const { return {v.dot(s), v.dot(t), v.dot(n)}; }
  Eigen::Vector3d FromLocal(const Eigen::Vector3d& v) const { return v.x() * s + v.y() * t + v.z() * n; }
};

// Polar angle from +z and azimuth from +x, for a unit vector (or any non-zero vector).
double PolarAngle(const Eigen::Vector3d& w);
double Azimuth(const Eigen::Vector3d& w);  // in (-pi, pi]; 0 along the pole
Eigen::Vector3d FromSpherical(double theta, double phi);

// Wraps an angle into (-pi, pi].
double WrapAngle(double angle);

// The full four-angle form (theta_i, phi_i, theta_e, phi_e) of a pair of local directions.
struct BrdfAngles {
  double theta_i = 0, phi_i = 0, theta_e = 0, phi_e = 0;
};
BrdfAngles ToBrdfAngles(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo);
void FromBrdfAngles(const BrdfAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo);

// The isotropic form: delta_phi = phi_e - phi_i, wrapped into (-pi, pi]. Its sign is kept, so that
// bilateral symmetry (delta_phi against -delta_phi) can be checked rather than assumed.
struct IsotropicAngles {
  double theta_i = 0, theta_e = 0, delta_phi = 0;
};
IsotropicAngles ToIsotropic(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo);
// The canonical pair with phi_i = 0: wi in the xz half-plane with x >= 0.
void FromIsotropic(const IsotropicAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo);

// Rusinkiewicz's half/difference angles: h = normalize(wi + wo); d is wi expressed in a frame where h
// is the pole (rotate by -phi_h about n, then by -theta_h about the binormal), exactly as the MERL
// reader computes them.
struct HalfDiffAngles {
  double theta_h = 0, phi_h = 0, theta_d = 0, phi_d = 0;
};
// Returns false (and zero angles) where wi + wo vanishes, so h is undefined (wi = -wo, which only
// happens at grazing).
bool ToHalfDiff(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, HalfDiffAngles* angles);
void FromHalfDiff(const HalfDiffAngles& angles, Eigen::Vector3d* wi, Eigen::Vector3d* wo);

}  // namespace ibrdf
