// Fuzz target: core/image_io.h ReadImageSpec and ReadPhotoMetadata through OpenImageIO: the same bytes
// as a DNG (OpenImageIO's raw reader, LibRaw) and as a TIFF, the headers and EXIF fields a session
// and `ibrdf session` read from a camera's files.
#include "core/image_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::MemoryFiles& files = ibrdf::fuzz::MemoryFiles::Get();
  for (const char* name : {"photo.dng", "photo.tif"}) {
    const std::string path = files.Put(name, data, size);
    ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] { ibrdf::ReadImageSpec(path); });
    ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] { ibrdf::ReadPhotoMetadata(path); });
  }
  return 0;
}
