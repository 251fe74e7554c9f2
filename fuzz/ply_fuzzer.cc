// Fuzz target: scan/ply_io.h ReadPly (ASCII and binary PLY, meshes, clouds and Stanford range grids).
#include "fuzz/fuzz_input.h"
#include "scan/ply_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("input.ply", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ReadPly(path); });
  return 0;
}
