// Samples for the reconstruct tests: a synthetic session rendered and derendered (reduced resolution
// where the bounds still hold, so the suite stays quick).
#pragma once

#include <vector>

#include "core/session.h"
#include "derender/derenderer.h"
#include "tests/test_util.h"

namespace ibrdf::testing {

inline std::vector<BrdfSample> SessionSamples(const BrdfModel& material, const CameraEffects& effects, int photos = 20,
                                              int width = 400, int height = 300) {
  ScratchDir dir;
  SynthOptions options;
  options.effects = effects;
  options.rig.num_photos = photos;
  options.rig.width = width;
  options.rig.height = height;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  return DerenderAnalytic(session, DerenderOptions()).samples;
}

}  // namespace ibrdf::testing
