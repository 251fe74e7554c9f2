// Fuzz target: core/rgl_bsdf.h RglBsdf (RGL .bsdf tensor files, read and checked as brdf-loader does).
#include "core/rgl_bsdf.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("input.bsdf", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::RglBsdf bsdf(path); });
  return 0;
}
