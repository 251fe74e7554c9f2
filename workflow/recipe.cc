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
  const std::string material = ResolvePath(fs::path(path).parent_path().string(), root.String("material"));
  recipe.material = fs::absolute(material).lexically_normal().string();
  RequireFile(recipe.material, root.Where("material"));
  const nlohmann::json& synth = root.Raw("synth");
  if (!synth.is_array()) ThrowError(root.Where("synth"), "expected an array of synth arguments (strings)");
  for (const nlohmann::json& arg : synth) {
    if (!arg.is_string()) ThrowError(root.Where("synth"), "expected strings, got " + JsonTypeName(arg));
    const std::string text = arg.get<std::string>();
    if (text == "--out" || text == "--material" || text == "--overwrite") {
      ThrowError(root.Where("synth"), text + " is set by `ibrdf run`, not by the recipe");
    }
    recipe.synth_args.push_back(text);
  }
  root.Finish();
  return recipe;
}

}  // namespace ibrdf
