// Registration of a scanned mesh to the world: the range scanner measured the platform's
// markers' corners in its own frame (the session's sample.scan_targets); the same markers' corners in
// the world are the known layout (targets.reference). The similarity world_from_mesh that maps the
// one onto the other is found in closed form (Umeyama 1991, "Least-squares estimation of
// transformation parameters between two point patterns"; Eigen::umeyama), in double and on centred
// coordinates, since scanner coordinates may lie kilometres from the origin.
//
// Each marker's residual (the RMS distance of its four corners from their world positions, after the
// transform) is reported. A marker above the threshold is tested by leave-one-out: the transform fitted
// without it, and its residual under that; the worst such marker is dropped and the fit repeated. Too
// few shared markers, a collinear layout (the rotation about the line is then determined only by each
// marker's own small extent) and residuals that stay above the threshold are refused with a message.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/rigid3.h"
#include "core/session.h"

namespace ibrdf {

struct MeshRegistrationOptions {
  int min_markers = 3;              // markers shared by the scan and the layout that the fit needs
  double max_marker_rms_m = 0.001;  // a marker's corner RMS above this (metres, world frame): outlier
  // A layout whose marker centres' second principal extent is below this fraction of the first is
  // collinear (degenerate).
  double min_spread_ratio = 0.05;
  bool estimate_scale = true;  // a similarity (a scanner may work in millimetres); false: rigid
  // At most this fraction of the shared markers (at least one) may be dropped as outliers; more
  // means the scan and the layout disagree, which is refused.
  double max_outlier_fraction = 0.25;

  bool Check(std::string* why) const;
};

struct MarkerRegistrationResidual {
  int id = -1;
  bool used = false;
  double rms_m = 0.0;             // corner RMS under the final transform, metres (world frame)
  double leave_one_out_m = -1.0;  // corner RMS under the fit without it; -1 where not tested
  std::string dropped_reason;     // empty when used
};

// A registration that passed every check (RegisterMeshToTargets throws Error otherwise).
struct MeshRegistration {
  Sim3d world_from_mesh;
  std::vector<MarkerRegistrationResidual> markers;  // the shared markers, in scan_targets' order
  std::vector<int> unmatched_ids;                   // scan targets whose id is not in the layout (ignored)
  int used_markers = 0;
  double rms_m = 0.0;             // over the used markers' corners, metres
  double max_marker_rms_m = 0.0;  // the worst used marker
  // "mesh registration: 12 of 12 markers, corner RMS 0.087 mm (worst 0.12 mm), scale 1.00002"
  std::string BriefReport() const;
};

// Registers the scan frame to the world. `where` names the scan targets' source in messages (e.g.
// "session.json: /sample/scan_targets"). Throws Error for too few shared markers, a collinear layout,
// or residuals above options.max_marker_rms_m that dropping outliers does not cure.
MeshRegistration RegisterMeshToTargets(const std::vector<ScanTargetSpec>& scan_targets,
                                       const std::vector<TargetSpec>& reference, const MeshRegistrationOptions& options,
                                       const std::string& where);

nlohmann::json ToJson(const MeshRegistration& registration);

}  // namespace ibrdf
