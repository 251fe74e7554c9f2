// Fuzz target: reconstruct/merl_table.h ReadMerl (MERL .binary tables).
#include "fuzz/fuzz_input.h"
#include "reconstruct/merl_table.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("input.binary", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ReadMerl(path); });
  return 0;
}
