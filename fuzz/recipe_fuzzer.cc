// Fuzz target: workflow/recipe.h ReadRecipe (a recipe.json). The folder holds material.json, which a
// recipe's "material" may name.
#include "fuzz/fuzz_input.h"
#include "workflow/recipe.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::MemoryFiles& files = ibrdf::fuzz::MemoryFiles::Get();
  files.Fixture("material.json", R"({"model": "lambertian", "albedo": [0.5, 0.5, 0.5]})");
  const std::string path = files.Put("recipe.json", data, size);
  ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] { ibrdf::ReadRecipe(path); });
  return 0;
}
