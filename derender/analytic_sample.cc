#include "derender/analytic_sample.h"

#include <cmath>
#include <type_traits>

#include "core/error.h"

namespace ibrdf {

AnalyticShape MakeAnalyticShape(const SampleSpec& spec) {
  switch (spec.kind) {
    case SampleSpec::Kind::kSphere:
      return SphereSample(spec.center, spec.radius);
    case SampleSpec::Kind::kCylinder:
      return CylinderSample(spec.center, spec.axis, spec.radius, spec.length);
    case SampleSpec::Kind::kMesh:
      break;
  }
  ThrowError("sample", "a mesh sample needs the mesh derenderer; the analytic derenderer takes a sphere or a cylinder");
}

std::unique_ptr<AnalyticSample> AnalyticSample::Create(const SampleSpec& spec) {
  return std::visit(
      [](const auto& shape) -> std::unique_ptr<AnalyticSample> {
        return std::make_unique<std::decay_t<decltype(shape)>>(shape);
      },
      MakeAnalyticShape(spec));
}

bool SphereSample::Contains(const Eigen::Vector3d& point) const {
  return (point - center_).squaredNorm() <= radius_ * radius_;
}

double CylinderSample::BoundingRadius() const { return std::hypot(radius_, half_length_); }

bool CylinderSample::Contains(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d f = point - center_;
  const double axial = f.dot(axis_);
  return std::abs(axial) <= half_length_ && (f - axial * axis_).squaredNorm() <= radius_ * radius_;
}

}  // namespace ibrdf
