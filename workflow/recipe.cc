#include "workflow/recipe.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"

namespace fs = std::filesystem;

namespace ibrdf {

Recipe ReadRecipe(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  JsonObject root(json, path);
  if (root.String("format") != "ibrdf-recipe") ThrowError(root.Where("format"), "expected \"ibrdf-recipe\"");
  if (root.Integer("version") != 1) ThrowError(root.Where("version"), "expected 1");
  Recipe recipe;
  recipe.path = path;
  recipe.name = root.String("name");
  root.String("description", "");
  root.String("paper", "");
  const std::string folder = fs::path(path).parent_path().string();
  const auto resolve = [&folder](const std::string& relative) {
    return fs::absolute(ResolvePath(folder, relative)).lexically_normal().string();
  };
  if (root.Has("material") == root.Has("material_map")) {
    ThrowError(root.Where("material"), root.Has("material")
                                           ? "give \"material\" or \"material_map\", not both"
                                           : "missing (or \"material_map\": a spatially varying sample)");
  }
  if (root.Has("material")) {
    recipe.material = resolve(root.String("material"));
    RequireFile(recipe.material, root.Where("material"));
  } else {
    recipe.material_map = resolve(root.String("material_map"));
    RequireFile(recipe.material_map, root.Where("material_map"));
    // The map's own material paths are relative to the map (MaterialMap::Load); they are the synth
    // stage's inputs too, so that editing one re-renders the session.
    const nlohmann::json map = ReadJsonFile(recipe.material_map);
    if (map.is_object() && map.contains("materials") && map["materials"].is_array()) {
      const std::string map_folder = fs::path(recipe.material_map).parent_path().string();
      for (const nlohmann::json& entry : map["materials"]) {
        if (entry.is_string()) {
          recipe.map_materials.push_back(
              fs::absolute(ResolvePath(map_folder, entry.get<std::string>())).lexically_normal().string());
        }
      }
    }
  }
  const nlohmann::json& synth = root.Raw("synth");
  if (!synth.is_array()) ThrowError(root.Where("synth"), "expected an array of synth arguments (strings)");
  for (const nlohmann::json& arg : synth) {
    if (!arg.is_string()) ThrowError(root.Where("synth"), "expected strings, got " + JsonTypeName(arg));
    const std::string text = arg.get<std::string>();
    if (text == "--out" || text == "--material" || text == "--overwrite") {
      ThrowError(root.Where("synth"), text + " is set by `ibrdf run`, not by the recipe");
    }
    if (text == "--material-map") {
      ThrowError(root.Where("synth"),
                 "--material-map is the recipe's \"material_map\" (a path relative to the recipe)");
    }
    recipe.synth_args.push_back(text);
  }
  root.Finish();
  return recipe;
}

}  // namespace ibrdf
