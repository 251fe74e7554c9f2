// Fuzz target: core/npy.h and core/sample_file.h: the same bytes read as a sample file (structured
// dtype) and as a plain float64 array, with and without the finiteness check.
#include "core/npy.h"
#include "core/sample_file.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("input.npy", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ReadSamples(path); });
  std::vector<size_t> shape;
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ReadNpyArray(path, &shape, true); });
  return 0;
}
