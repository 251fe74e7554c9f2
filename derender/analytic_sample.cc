#include "derender/analytic_sample.h"

#include <cmath>

#include "core/error.h"

namespace ibrdf {

std::unique_ptr<AnalyticSample> AnalyticSample::Create(const SampleSpec& spec) {
  switch (spec.kind) {
    case SampleSpec::Kind::kSphere:
      return std::make_unique<SphereSample>(spec.center, spec.radius);
    case SampleSpec::Kind::kCylinder:
      return std::make_unique<CylinderSample>(spec.center, spec.axis, spec.radius, spec.length);
    case SampleSpec::Kind::kMesh:
      break;
  }
  ThrowError("sample", "a mesh sample needs the mesh derenderer; the analytic derenderer takes a sphere or a cylinder");
}

// Ray/sphere in the form of Haines et al., "Precision improvements for ray/sphere intersection" (Ray
// Tracing Gems, ch. 7): the discriminant from the ray's closest approach, and the far root from the
// near one by Vieta, so a small sphere far from the camera keeps its digits.
bool SphereSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const {
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

bool SphereSample::Contains(const Eigen::Vector3d& point) const {
  return (point - center_).squaredNorm() <= radius_ * radius_;
}

double CylinderSample::BoundingRadius() const { return std::hypot(radius_, half_length_); }

bool CylinderSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const {
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

bool CylinderSample::Contains(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d f = point - center_;
  const double axial = f.dot(axis_);
  return std::abs(axial) <= half_length_ && (f - axial * axis_).squaredNorm() <= radius_ * radius_;
}

}  // namespace ibrdf
