// Fuzz target: core/brdf_model.h LoadMaterial (material JSON files), and one evaluation of what it
// loads, so that accepted values are checked to be usable.
#include <cmath>

#include "core/brdf_model.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("material.json", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::LoadMaterial(path); });
  return 0;
}
