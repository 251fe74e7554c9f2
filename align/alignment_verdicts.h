// The verdicts of an alignment (core/verdict.h; bounds in docs/verdicts.md): photos posed, the
// reprojection RMS, the sphere's radius against the stated one and its centre against the stated
// centre, the limb evidence's balance, the light's marker spread, the mesh registration's RMS, and a
// cylinder's fit to its markers (fitted at all, its corner RMS, markers left out).
#pragma once

#include <optional>
#include <vector>

#include "align/aligner.h"
#include "align/mesh_registration.h"
#include "core/session.h"
#include "core/verdict.h"

namespace ibrdf {

struct AlignmentVerdictBounds {
  double warn_photos_posed = 1.0;    // fraction of measurement photos posed below this: warn
  double fail_photos_posed = 0.5;    // below this: fail (most of the coverage is gone)
  double warn_rms_px = 0.5;          // bundle adjustment's corner RMS over this: warn
  double fail_rms_px = 1.0;          // over this: fail (photos over AlignOptions::max_image_rms_px are dropped)
  double warn_radius_ratio = 1.25;   // fitted / stated radius outside [1/r, r]: warn
  double fail_radius_ratio = 2.0;    // outside [1/r, r]: fail (a sphere fit that collapsed or blew up)
  double warn_center_shift_radii = 1.0;  // fitted centre this many stated radii from the stated one: warn
  double fail_center_shift_radii = 4.0;  // more: fail (the sphere is not where the session put it)
  double warn_light_spread_m = 2e-3;     // light markers' estimates disagree by more: warn
  double fail_light_spread_m = 10e-3;    // more: fail
  double warn_mesh_rms_m = 0.5e-3;       // mesh registration's corner RMS over this: warn
  double fail_mesh_rms_m = 2e-3;         // over this: fail
  double warn_cylinder_rms_m = 0.5e-3;   // cylinder fit's corner RMS over this: warn
  double fail_cylinder_rms_m = 2e-3;     // over this: fail
};

// The verdicts over `result`, the alignment of `input` (whose sample and photos are the stated
// values); `registration` when the scanned mesh was registered.
std::vector<Verdict> AlignmentVerdicts(const Session& input, const AlignResult& result,
                                       const std::optional<MeshRegistration>& registration,
                                       const AlignmentVerdictBounds& bounds = AlignmentVerdictBounds());

}  // namespace ibrdf
