// Fuzz target: align/colmap_model.h ColmapModel::ReadBinary. The input holds cameras.bin, images.bin
// and points3D.bin separated by the marker of fuzz_input.h.
#include "align/colmap_model.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::vector<std::string> parts = ibrdf::fuzz::SplitParts(data, size, 3);
  const char* names[3] = {"cameras.bin", "images.bin", "points3D.bin"};
  for (int i = 0; i < 3; ++i) {
    ibrdf::fuzz::MemoryFiles::Get().Put(names[i], parts[i]);
  }
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ColmapModel::ReadBinary(dir).Validate(dir); });
  return 0;
}
