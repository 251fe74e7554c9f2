// A recipe: a synthetic experiment, samples/<name>/recipe.json, naming a material and `ibrdf synth`'s
// options; `ibrdf run` on a recipe renders the session first (docs/workflow.md, "Recipes").
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

struct Recipe {
  std::string path;                     // the recipe.json file
  std::string name;                     // the experiment's name
  std::string material;                 // the material file, absolute
  std::vector<std::string> synth_args;  // synth's options, except --material, --out and --overwrite
};

// Reads and checks a recipe.json: unknown keys, a wrong format or version, a missing material or a
// synth argument that `ibrdf run` sets itself are Errors naming the file and the field.
Recipe ReadRecipe(const std::string& path);

}  // namespace ibrdf
