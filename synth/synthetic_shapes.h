// Irregular true shapes for synthetic mesh measurements: a squash, a clay pot and a dented
// sphere, each an exact implicit surface with exact ray hits and exact normals, so that a session
// measured through a simulated range scan can be compared with the geometry it came from.
//
// Every shape is a solid {p : F(p) <= 0} around a centre, with F evaluated in coordinates relative to
// that centre (a scene 10 km from the origin keeps its digits). Ray hits: Lipschitz-bounded sphere
// tracing (Hart 1996, "Sphere tracing") from the bounding sphere, each step max(F / L, kMinStep) with L
// a bound on |grad F| outside the solid, so no surface is skipped except where the ray's whole
// excursion into the solid is shallower than L * kMinStep / 2 (about a micrometre: the stated
// tolerance for thin grazing hits); the first sign change then brackets the hit, refined by Newton's
// method safeguarded by bisection, in double. Normals are grad F, normalized.
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "derender/analytic_sample.h"

namespace ibrdf {

class ImplicitSample : public AnalyticSample {
 public:
  // Smallest ray-marching step, metres; a ray entering the solid less deeply than
  // Lipschitz() * kMinStep / 2 may be reported as a miss.
  static constexpr double kMinStep = 1e-6;

  explicit ImplicitSample(const Eigen::Vector3d& center) : center_(center) {}

  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const override;
  bool Contains(const Eigen::Vector3d& point) const override;
  Eigen::Vector3d BoundingCenter() const override { return center_; }
  double BoundingRadius() const override { return bounding_radius_; }

  // F at `local` (a point relative to the centre, metres) and its gradient; F < 0 inside.
  virtual double Evaluate(const Eigen::Vector3d& local, Eigen::Vector3d* gradient) const = 0;
  // A bound on |grad F| outside the solid.
  double Lipschitz() const { return lipschitz_; }
  // The lowest height of the surface relative to the centre (metres, <= 0): where it rests on a
  // platform. Exact for the pot, within 1 micrometre (a dense search) for the others.
  double LowestZ() const { return lowest_z_; }
  // The surface point along the ray from the centre in direction `u` (unit) and its outward normal:
  // every shape here is star-shaped about its centre (the fine truth mesh samples it this way).
  Eigen::Vector3d RadialPoint(const Eigen::Vector3d& u, Eigen::Vector3d* normal) const;
  // The shape's name and parameters (truth.json).
  virtual nlohmann::json Describe() const = 0;

 protected:
  Eigen::Vector3d center_;
  double bounding_radius_ = 0.0;  // every surface point lies within it of the centre
  double lipschitz_ = 1.0;
  double lowest_z_ = 0.0;
};

// A solid star-shaped about its centre: |p| <= r(p / |p|), with F = |p| - r(u). Outside the solid
// |grad F| = sqrt(1 + |grad_S r|^2 / |p|^2) <= sqrt(1 + (max |grad_S r| / min r)^2); both extremes come
// from a dense search over directions, with a 25 % margin on the gradient.
class StarShapedSample : public ImplicitSample {
 public:
  using ImplicitSample::ImplicitSample;
  double Evaluate(const Eigen::Vector3d& local, Eigen::Vector3d* gradient) const override;
  // r(u) for a unit direction (local frame) and its gradient with respect to u (any smooth extension
  // off the unit sphere; only the tangential part is used).
  virtual double Radius(const Eigen::Vector3d& u, Eigen::Vector3d* gradient) const = 0;

 protected:
  // Computes the bounding radius, the Lipschitz bound and the lowest point; subclasses call it at the
  // end of their constructor.
  void InitBounds();
};

// A squash: an ellipsoid with a fuller side, shallow ribs and a flattened stem end (about 9 cm wide,
// 7 cm tall):
//   r(u) = r_ellipsoid(u) (1 + asymmetry u_x + rib_depth Re((u_x + i u_y)^ribs)) (1 - stem_flattening w^2),
// w = max(0, (u_z - stem_cos) / (1 - stem_cos)). The rib term fades towards the poles as sin^ribs of
// the polar angle; the stem term is C1 at u_z = stem_cos.
struct SquashParams {
  Eigen::Vector3d semi_axes = Eigen::Vector3d(0.046, 0.042, 0.036);  // metres: x, y, z (z up)
  double asymmetry = 0.06;                                           // the +x side fuller by this fraction
  int ribs = 8;                                                      // ribs around the vertical axis
  double rib_depth = 0.012;                                          // relative amplitude of the ribs at the equator
  double stem_flattening = 0.12;  // relative flattening at the top pole (0.12: nearly flat, still convex)
  double stem_cos = 0.5;          // flattening starts at this u_z (60 degrees from the pole)
  bool Check(std::string* why) const;
};

class SquashSample : public StarShapedSample {
 public:
  SquashSample(const Eigen::Vector3d& center, const SquashParams& params);
  double Radius(const Eigen::Vector3d& u, Eigen::Vector3d* gradient) const override;
  nlohmann::json Describe() const override;

 private:
  SquashParams params_;
};

// A dented sphere: r(u) = radius (1 - depth s(w)), w = (u . axis - cos(dent_half_angle)) /
// (1 - cos(dent_half_angle)) clamped to [0, 1], s(w) = w^2 (3 - 2 w) (smoothstep: flat at the rim and
// at the bottom). Not convex: the dent's rim shadows its floor when the light comes from the side.
struct DentParams {
  double radius = 0.045;              // metres
  double depth = 0.4;                 // dent depth as a fraction of the radius
  double dent_half_angle_deg = 32.0;  // angular radius of the dent seen from the centre
  // Dent axis (local frame, normalized on use): 70 degrees round from the light (+x) towards the
  // synth cameras' arc and 25 degrees up, so cameras see it and the light grazes it from the side.
  Eigen::Vector3d axis = Eigen::Vector3d(0.3100, 0.8517, 0.4226);
  bool Check(std::string* why) const;
};

class DentedSphereSample : public StarShapedSample {
 public:
  DentedSphereSample(const Eigen::Vector3d& center, const DentParams& params);
  double Radius(const Eigen::Vector3d& u, Eigen::Vector3d* gradient) const override;
  nlohmann::json Describe() const override;
  // True for surface directions inside the dent (u . axis > cos(dent_half_angle)).
  bool InDent(const Eigen::Vector3d& u) const;

 private:
  DentParams params_;
  Eigen::Vector3d axis_;
  double cos_half_angle_ = 0.0;
};

// A clay pot: a solid of revolution about z whose profile is part cone (the lower body, narrowing to
// a flat foot) and part cylinder (the upper body, to a flat top), with every edge rounded: the points
// within `fillet` of the revolved convex hexagon with vertices (+-foot_radius, bottom_z),
// (+-body_radius, cone_top_z), (+-body_radius, top_z). Decision: smoothly joined (the rounding makes
// the surface C1 everywhere: no crease for local-plane normals to smear). F is the exact signed
// distance (the 2D distance in the meridian plane), so L = 1. Outer size: radius body_radius + fillet,
// height top_z - bottom_z + 2 fillet.
struct PotParams {
  double foot_radius = 0.026;  // metres (hexagon)
  double body_radius = 0.038;  // metres (hexagon; the cylinder's radius is this + fillet)
  double bottom_z = -0.036;    // metres, relative to the centre
  double cone_top_z = -0.004;  // where the cone meets the cylinder
  double top_z = 0.036;
  double fillet = 0.005;  // metres: the rounding radius of every edge
  bool Check(std::string* why) const;
};

class PotSample : public ImplicitSample {
 public:
  PotSample(const Eigen::Vector3d& center, const PotParams& params);
  double Evaluate(const Eigen::Vector3d& local, Eigen::Vector3d* gradient) const override;
  nlohmann::json Describe() const override;

 private:
  // Signed distance from (rho, z) to the hexagon, and its gradient in (rho, z).
  double Profile(const Eigen::Vector2d& q, Eigen::Vector2d* gradient) const;
  PotParams params_;
  std::vector<Eigen::Vector2d> hexagon_;  // counter-clockwise in (rho, z)
};

}  // namespace ibrdf
