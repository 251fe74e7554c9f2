#include "derender/synthetic_targets.h"

#include <cmath>

namespace ibrdf {

SampleTargetsSpec SampleTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* world_corners) {
  SampleTargetsSpec spec;
  if (world_corners) world_corners->clear();
  if (!options.targets || options.sample != SampleSpec::Kind::kCylinder ||
      options.shape != SynthOptions::Shape::kNone) {
    return spec;
  }
  // The sample frame: origin at the cylinder's centre (options.origin), axes along the world's (the
  // synthetic cylinder's axis is world z).
  const double half = 0.5 * options.sample_marker_size;
  const double cap = 0.5 * options.cylinder_length;
  const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = -Eigen::Vector3d::UnitY();
  for (int k = 0; k < options.sample_marker_count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.25) / options.sample_marker_count;
    const Eigen::Vector3d center(options.sample_marker_radius * std::cos(angle),
                                 options.sample_marker_radius * std::sin(angle), cap);
    TargetSpec target;
    target.id = options.sample_marker_first_id + k;
    target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                      center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
    spec.markers.push_back(target);
    if (world_corners) {
      TargetSpec world = target;
      for (Eigen::Vector3d& c : world.corners) c += options.origin;
      world_corners->push_back(world);
    }
  }
  return spec;
}

}  // namespace ibrdf
