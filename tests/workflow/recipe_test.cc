// Tests of workflow/recipe.h: a recipe names its material (resolved against the recipe) and synth's
// options; arguments `ibrdf run` sets itself and unknown keys are Errors naming the field.
#include "workflow/recipe.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using nlohmann::json;
using testing::ScratchDir;

json ValidRecipe() {
  return {{"format", "ibrdf-recipe"}, {"version", 1},      {"name", "unit"},
          {"material", "../m.json"},  {"paper", "MWL+99"}, {"synth", {"--sample", "sphere"}}};
}

TEST(Recipe, ReadsMaterialAndSynthArguments) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "r");
  std::ofstream(dir / "m.json") << "{}";
  std::ofstream(dir / "r/recipe.json") << ValidRecipe().dump();
  const Recipe recipe = ReadRecipe(dir / "r/recipe.json");
  EXPECT_EQ(recipe.name, "unit");
  EXPECT_EQ(recipe.material, std::filesystem::absolute(dir / "m.json").lexically_normal().string());
  EXPECT_EQ(recipe.synth_args, (std::vector<std::string>{"--sample", "sphere"}));

  auto with = [](const std::string& key, const json& value) {
    json changed = ValidRecipe();
    changed[key] = value;
    return changed;
  };
  for (const json& bad : {with("synth", {"--out", "x"}), with("colour", "red"), with("material", "missing.json")}) {
    std::ofstream(dir / "r/recipe.json") << bad.dump();
    try {
      ReadRecipe(dir / "r/recipe.json");
      ADD_FAILURE() << bad.dump();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(dir / "r/recipe.json: /"), std::string::npos) << e.what();
    }
  }
}

TEST(Recipe, MaterialMapResolvesAgainstTheRecipeAndReplacesTheMaterial) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "r");
  std::filesystem::create_directories(dir / "materials");
  std::ofstream(dir / "m.json") << "{}";
  std::ofstream(dir / "materials/a.json") << "{}";
  std::ofstream(dir / "r/map.json")
      << json{{"kind", "stripes"}, {"materials", {"../materials/a.json", {{"material", json::object()}}}}}.dump();
  json with_map = ValidRecipe();
  with_map.erase("material");
  with_map["material_map"] = "map.json";
  std::ofstream(dir / "r/recipe.json") << with_map.dump();
  const Recipe recipe = ReadRecipe(dir / "r/recipe.json");
  EXPECT_EQ(recipe.material, "");
  EXPECT_EQ(recipe.material_map, std::filesystem::absolute(dir / "r/map.json").lexically_normal().string());
  // The map's material files, relative to the map, are the synth stage's inputs (embedded ones are not files).
  const std::string a = std::filesystem::absolute(dir / "materials/a.json").lexically_normal().string();
  EXPECT_EQ(recipe.map_materials, (std::vector<std::string>{a}));

  json both = with_map;
  both["material"] = "../m.json";
  json neither = with_map;
  neither.erase("material_map");
  json flag = with_map;
  flag["synth"] = {"--material-map", "map.json"};
  json missing = with_map;
  missing["material_map"] = "none.json";
  for (const json& bad : {both, neither, flag, missing}) {
    std::ofstream(dir / "r/recipe.json") << bad.dump();
    try {
      ReadRecipe(dir / "r/recipe.json");
      ADD_FAILURE() << bad.dump();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(dir / "r/recipe.json: /"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("material"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace ibrdf
