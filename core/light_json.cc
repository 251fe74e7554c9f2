#include "core/light_json.h"

#include <nlohmann/json.hpp>

#include "core/json_reader.h"

namespace ibrdf {

nlohmann::json LightJson(const Light& light) {
  nlohmann::json l;
  if (!light.id.empty()) l["id"] = light.id;
  l["kind"] = LightKindName(light.kind);
  l[LightPlacementKey(light.kind)] = ToJson(LightPlacement(light));
  if (light.has_intensity) l["intensity"] = ToJson(light.intensity);
  return l;
}

}  // namespace ibrdf
