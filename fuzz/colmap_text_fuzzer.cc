// Fuzz target: align/colmap_model.h ColmapModel::ReadText. The input holds cameras.txt, images.txt
// and points3D.txt separated by the marker of fuzz_input.h.
#include "align/colmap_model.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::vector<std::string> parts = ibrdf::fuzz::SplitParts(data, size, 3);
  const char* names[3] = {"cameras.txt", "images.txt", "points3D.txt"};
  for (int i = 0; i < 3; ++i) {
    ibrdf::fuzz::MemoryFiles::Get().Put(names[i], parts[i]);
  }
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::ColmapModel::ReadText(dir).Validate(dir); });
  return 0;
}
