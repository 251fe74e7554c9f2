// A recipe: a synthetic experiment, samples/<name>/recipe.json, naming a material and `ibrdf synth`'s
// options; `ibrdf run` on a recipe renders the session first (docs/workflow.md, "Recipes").
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

struct Recipe {
  std::string path;      // the recipe.json file
  std::string name;      // the experiment's name
  std::string material;  // the material file, absolute ("" with a material map)
  // A spatially varying sample instead of one material (synth --material-map): the map file, absolute,
  // and the material files it names, absolute (the synth stage's inputs); "" and empty without one.
  std::string material_map;
  std::vector<std::string> map_materials;
  std::vector<std::string> synth_args;  // synth's options, except --material(-map), --out and --overwrite
};

// Reads and checks a recipe.json: unknown keys, a wrong format or version, both or neither of
// "material" and "material_map" (each a path relative to the recipe), a missing file or a synth
// argument that `ibrdf run` sets itself are Errors naming the file and the field.
Recipe ReadRecipe(const std::string& path);

}  // namespace ibrdf
