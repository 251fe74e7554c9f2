// Analytic sample shapes for the paper's sphere and cylinder measurements: exact ray intersection and
// exact normals, no mesh (a scene models only what it needs).
#pragma once

#include <cmath>
#include <memory>
#include <variant>

#include <Eigen/Core>

#include "core/session.h"

namespace ibrdf {

struct SurfaceHit {
  double t = 0.0;                                    // ray parameter, metres along a unit direction
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // world frame
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, outward (a mesh: interpolated; zero if none)
  // Mesh samples only (analytic shapes leave the defaults): the face's own unit normal, the face hit,
  // and the quality of the interpolated normal's local-plane fit (scan/local_plane_normals.h).
  Eigen::Vector3d geometric_normal = Eigen::Vector3d::Zero();
  int face = -1;
  float fit_rms_m = -1.0f;  // RMS residual of the fit, metres, interpolated; < 0: unknown
  int fit_neighbours = -1;  // fewest points in the fits of the face's corners; < 0: unknown
};

// What the derenderer needs of a sample's surface: rays hit it, a camera must be outside it, and a
// bounding sphere culls the pixels that cannot see it. Analytic shapes (below) and the scanned mesh
// (mesh_sample.h) implement it.
class SampleSurface {
 public:
  virtual ~SampleSurface() = default;
  // The nearest hit with t > 0 of the ray origin + t * direction (direction unit length) on the
  // measured surface. False for a miss, for a ray that starts inside, and (cylinder) for rays that hit
  // an end cap first: the caps are not measured.
  virtual bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const = 0;
  // True if the point is inside the solid (a camera there sees no outer surface).
  virtual bool Contains(const Eigen::Vector3d& point) const = 0;
  // A bounding sphere: centre and radius (framing synthetic views, culling pixels).
  virtual Eigen::Vector3d BoundingCenter() const = 0;
  virtual double BoundingRadius() const = 0;
  // True if the sample itself blocks the segment from `from` to `to` (a shadow ray; `from` on the
  // surface). The default suits convex shapes, which never shadow themselves.
  virtual bool Occluded(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const { return false; }
};

// The paper's analytic shapes: exact intersections and normals, no mesh.
class AnalyticSample : public SampleSurface {
 public:
  // A sphere or cylinder from a session's sample; throws Error for a mesh sample.
  static std::unique_ptr<AnalyticSample> Create(const SampleSpec& spec);
};

// final, and Intersect inline (below): the derenderer calls it per pixel through the concrete type.
// Declared inline in the class so that it is not the key function: the vtable stays in
// analytic_sample.cc (with Contains), not in every file that includes this header.
class SphereSample final : public AnalyticSample {
 public:
  SphereSample(const Eigen::Vector3d& center, double radius) : center_(center), radius_(radius) {}
  inline bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                        SurfaceHit* hit) const override;
  bool Contains(const Eigen::Vector3d& point) const override;
  Eigen::Vector3d BoundingCenter() const override { return center_; }
  double BoundingRadius() const override { return radius_; }

 private:
  Eigen::Vector3d center_;
  double radius_;
};

// A closed circular cylinder: the curved side is the sample, the end caps are unmeasured (black).
class CylinderSample final : public AnalyticSample {
 public:
  CylinderSample(const Eigen::Vector3d& center, const Eigen::Vector3d& axis, double radius, double length)
      : center_(center), axis_(axis.normalized()), radius_(radius), half_length_(0.5 * length) {}
  inline bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                        SurfaceHit* hit) const override;
  bool Contains(const Eigen::Vector3d& point) const override;
  Eigen::Vector3d BoundingCenter() const override { return center_; }
  double BoundingRadius() const override;

 private:
  Eigen::Vector3d center_;
  Eigen::Vector3d axis_;
  double radius_;
  double half_length_;
};

// Ray/sphere in the form of Haines et al., "Precision improvements for ray/sphere intersection" (Ray
// Tracing Gems, ch. 7): the discriminant from the ray's closest approach, and the far root from the
// near one by Vieta, so a small sphere far from the camera keeps its digits.
inline bool SphereSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                    SurfaceHit* hit) const {
  const Eigen::Vector3d f = origin - center_;
  const double b = f.dot(direction);
  const double c = f.squaredNorm() - radius_ * radius_;
  if (c <= 0.0) return false;  // starts inside (or on) the sphere
  if (b >= 0.0) return false;  // sphere behind the ray
  const Eigen::Vector3d closest = f - b * direction;
  const double discriminant = radius_ * radius_ - closest.squaredNorm();
  if (discriminant < 0.0) return false;
  const double q = -b + std::sqrt(discriminant);  // > 0
  hit->t = c / q;                                 // the near root
  hit->point = origin + hit->t * direction;
  // The normal from the centre offset along the ray, not from the absolute point: no cancellation
  // when the scene is far from the origin.
  hit->normal = ((f + hit->t * direction) / radius_).normalized();
  return true;
}

inline bool CylinderSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                      SurfaceHit* hit) const {
  const Eigen::Vector3d f = origin - center_;
  const double f_axial = f.dot(axis_);
  const double d_axial = direction.dot(axis_);
  const Eigen::Vector3d f_perp = f - f_axial * axis_;
  const Eigen::Vector3d d_perp = direction - d_axial * axis_;
  const double a = d_perp.squaredNorm();
  if (!(a > 1e-24)) return false;  // parallel to the axis: only a cap could be hit
  const double c = f_perp.squaredNorm() - radius_ * radius_;
  if (c <= 0.0) return false;  // inside the infinite cylinder: no outer side surface ahead
  const double b = f_perp.dot(d_perp);
  if (b >= 0.0) return false;
  // |f_perp + t d_perp|^2 = a (t - t_mid)^2 + |closest|^2 with t_mid = -b / a.
  const Eigen::Vector3d closest = f_perp - (b / a) * d_perp;
  const double discriminant = radius_ * radius_ - closest.squaredNorm();
  if (discriminant < 0.0) return false;
  const double q = -b + std::sqrt(a * discriminant);
  const double t = c / q;  // the near root
  const double axial = f_axial + t * d_axial;
  if (std::abs(axial) > half_length_) return false;  // above or below the side: a cap, or a miss
  hit->t = t;
  hit->point = origin + t * direction;
  hit->normal = ((f_perp + t * d_perp) / radius_).normalized();
  return true;
}

// A sphere or a cylinder by value: a caller that picks the shape once and then calls its inline
// Intersect per pixel (the derenderer's kernel, through std::visit) holds this, not a base pointer.
using AnalyticShape = std::variant<SphereSample, CylinderSample>;

// The session's sphere or cylinder; throws Error for a mesh sample.
AnalyticShape MakeAnalyticShape(const SampleSpec& spec);

}  // namespace ibrdf
