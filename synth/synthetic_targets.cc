#include "synth/synthetic_targets.h"

#include <cmath>

#include "align/targets.h"
#include "synth/synthetic.h"

namespace ibrdf {

double PlatformHeight(const SynthSceneOptions& scene) {
  if (scene.shape != SynthShape::kNone) return scene.origin.z() + MakeTrueShape(scene)->LowestZ();
  switch (scene.sample) {
    case SampleSpec::Kind::kSphere:
      return scene.origin.z() - scene.sample_radius;
    case SampleSpec::Kind::kCylinder:
      return scene.origin.z() - 0.5 * scene.cylinder_length;
    case SampleSpec::Kind::kMesh:
      break;  // a scene's mesh is a shape (handled above); SynthSceneOptions::Check refuses kMesh
  }
  UnhandledKind("SampleSpec::Kind", static_cast<int>(scene.sample));
}

std::vector<TargetSpec> TargetLayout(const SynthOptions& options) {
  std::vector<TargetSpec> layout;
  const SynthTargetOptions& targets = options.targets;
  if (!targets.enabled) return layout;
  const Eigen::Vector3d& origin = options.scene.origin;
  const double z = PlatformHeight(options.scene);
  const double half = 0.5 * targets.marker_size;
  // Printed upright for a viewer above: x east, y south, so x cross y points down into the platform.
  const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = -Eigen::Vector3d::UnitY();
  for (int k = 0; k < targets.ring_count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.5) / targets.ring_count;
    const Eigen::Vector3d center = Eigen::Vector3d(origin.x(), origin.y(), z) +
                                   targets.ring_radius * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    TargetSpec target;
    target.id = k;
    target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                      center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
    layout.push_back(target);
  }
  return layout;
}

LightTargetsSpec LightTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* corners) {
  LightTargetsSpec spec;
  const SynthTargetOptions& targets = options.targets;
  if (corners) corners->clear();
  if (!targets.enabled || targets.light_photos <= 0) return spec;
  spec.size = targets.light_marker_size;
  const Eigen::Vector3d light = options.scene.origin + options.scene.light_distance * Eigen::Vector3d::UnitX();
  // Printed upright for a viewer at the sample looking at the light: x along -y, y down (-z), so
  // x cross y (into the print) points away from the sample, along +x.
  const Eigen::Vector3d x_axis = -Eigen::Vector3d::UnitY(), y_axis = -Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d world_from_marker;
  world_from_marker << x_axis, y_axis, x_axis.cross(y_axis);
  const double pitch = targets.light_marker_size * (1.0 + 2.0 * targets.card_margin);
  const double half = 0.5 * targets.light_marker_size;
  for (int k = 0; k < targets.light_marker_count; ++k) {
    const Eigen::Vector3d center = light - targets.light_card_drop * Eigen::Vector3d::UnitZ() +
                                   pitch * (k - 0.5 * (targets.light_marker_count - 1)) * x_axis;
    LightMarkerSpec marker;
    marker.id = targets.light_marker_first_id + k;
    marker.light_in_marker = world_from_marker.transpose() * (light - center);
    spec.markers.push_back(marker);
    if (corners) {
      TargetSpec target;
      target.id = marker.id;
      target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                        center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
      corners->push_back(target);
    }
  }
  return spec;
}

SampleTargetsSpec SampleTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* world_corners) {
  SampleTargetsSpec spec;
  const SynthSceneOptions& scene = options.scene;
  const SynthTargetOptions& targets = options.targets;
  if (world_corners) world_corners->clear();
  if (!targets.enabled || scene.sample != SampleSpec::Kind::kCylinder || scene.shape != SynthShape::kNone) {
    return spec;
  }
  // The sample frame: origin at the cylinder's centre (scene.origin), axes along the world's (the
  // synthetic cylinder's axis is world z).
  const double half = 0.5 * targets.sample_marker_size;
  const double cap = 0.5 * scene.cylinder_length;
  const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = -Eigen::Vector3d::UnitY();
  for (int k = 0; k < targets.sample_marker_count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.25) / targets.sample_marker_count;
    const Eigen::Vector3d center(targets.sample_marker_radius * std::cos(angle),
                                 targets.sample_marker_radius * std::sin(angle), cap);
    TargetSpec target;
    target.id = targets.sample_marker_first_id + k;
    target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                      center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
    spec.markers.push_back(target);
    if (world_corners) {
      TargetSpec world = target;
      for (Eigen::Vector3d& c : world.corners) c += scene.origin;
      world_corners->push_back(world);
    }
  }
  return spec;
}

WhiteReferenceTargetsSpec SynthWhiteCardLayout(const SynthOptions& options) {
  const SynthTargetOptions& targets = options.targets;
  if (!targets.white_card) return WhiteReferenceTargetsSpec();
  return WhiteCardLayout(targets.white_marker_first_id, targets.white_marker_size, options.radiometry.white_size,
                         targets.card_margin, 0.0);
}

}  // namespace ibrdf
