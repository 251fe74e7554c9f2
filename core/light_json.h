// A light as the session format writes it (docs/session-format.md, "lights"): the one writer of light
// objects, used by the session's manifest, the "ibrdf-lights" files, synthetic mirror-sphere sessions
// and the report.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "core/light.h"

namespace ibrdf {

// id (when named), kind, position (point) or direction (directional), and intensity (when stated).
nlohmann::json LightJson(const Light& light);

}  // namespace ibrdf
