// Markers fixed to a synthetic cylinder (the align stage's cylinder fit, align/cylinder_fit.h): small
// ArUco markers printed on the cylinder's top end cap, near its rim, which the measurement photos see
// from above (the caps are not measured). Their corners in the cylinder's own frame go into the
// session's targets.sample block; their world corners into the renderer's cap board.
#pragma once

#include <vector>

#include "core/session.h"
#include "derender/synthetic.h"

namespace ibrdf {

// The sample markers of a synthetic session: `sample_marker_count` markers of side
// `sample_marker_size`, ids from `sample_marker_first_id`, centred `sample_marker_radius` from the axis
// on the top cap, evenly spaced in azimuth and printed upright for a viewer above (x east, y south).
// Empty unless options.targets is on and the sample is a cylinder. `world_corners` (optional) gets
// their corners in the world frame.
SampleTargetsSpec SampleTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* world_corners);

}  // namespace ibrdf
