// The coded targets of a synthetic session (SynthTargetOptions): the ring of ArUco markers on the
// platform under the sample (the align stage's reference), the card of markers on the light (its
// position), and small markers printed on a cylinder's top end cap near its rim (the cylinder fit,
// align/cylinder_fit.h), which the measurement photos see from above (the caps are not measured).
// Their corners go into the session's targets block; their world corners into the renderer's boards.
#pragma once

#include <vector>

#include "core/session.h"
#include "synth/synth_options.h"

namespace ibrdf {

// The platform plane's height (world z): the sample rests on it.
double PlatformHeight(const SynthSceneOptions& scene);

// The reference markers' corners of a target session (empty when the targets are off).
std::vector<TargetSpec> TargetLayout(const SynthOptions& options);

// The light's markers of a target session: their world corners (`corners`, optional) and the session's
// description of them (the light's offset in each marker's frame). Empty when there are none.
LightTargetsSpec LightTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* corners);

// The sample markers of a synthetic session: `sample_marker_count` markers of side
// `sample_marker_size`, ids from `sample_marker_first_id`, centred `sample_marker_radius` from the axis
// on the top cap, evenly spaced in azimuth and printed upright for a viewer above (x east, y south).
// Empty unless the targets are on and the sample is a cylinder. `world_corners` (optional) gets
// their corners in the world frame.
SampleTargetsSpec SampleTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* world_corners);

// The white reference's card markers of a synthetic session (targets.white_card): align/targets.h's
// WhiteCardLayout for the patch (radiometry.white_size), the card's markers and card_margin, the patch
// flush with the card. Empty unless white_card.
WhiteReferenceTargetsSpec SynthWhiteCardLayout(const SynthOptions& options);

}  // namespace ibrdf
