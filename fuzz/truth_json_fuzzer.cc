// Fuzz target: reconstruct/truth_comparison.h LoadTruthMaterial (a synthetic session's truth.json).
#include "fuzz/fuzz_input.h"
#include "reconstruct/truth_comparison.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("truth.json", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::LoadTruthMaterial(path); });
  return 0;
}
