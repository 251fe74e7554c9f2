#include "core/truth_file.h"

#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "core/rgl_bsdf.h"

namespace ibrdf {

bool IsSpatiallyVaryingTruth(const std::string& path) {
  if (IsMerlPath(path) || IsRglBsdfPath(path)) return false;
  const nlohmann::json json = ReadJsonFile(path);
  return json.is_object() && json.contains("format") && json.contains("material_map");
}

}  // namespace ibrdf
