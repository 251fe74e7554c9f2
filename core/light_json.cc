#include "core/light_json.h"

#include <nlohmann/json.hpp>

#include "core/json_reader.h"

namespace ibrdf {

nlohmann::json LightJson(const Light& light) {
  nlohmann::json l;
  if (!light.id.empty()) l["id"] = light.id;
  l["kind"] = LightKindName(light.kind);
  if (light.placement_known) {
    l[LightPlacementKey(light.kind)] = ToJson(LightPlacement(light));
  } else {
    l[LightPlacementKey(light.kind)] = "unknown";
  }
  if (light.has_intensity) l["intensity"] = ToJson(light.intensity);
  return l;
}

}  // namespace ibrdf
