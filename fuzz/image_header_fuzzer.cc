// Fuzz target: core/image_io.h ReadImageSpec and ReadPhotoMetadata through OpenImageIO: the same bytes
// as a DNG (OpenImageIO's raw reader, LibRaw) and as a TIFF, the headers and EXIF fields a session
// and `ibrdf session` read from a camera's files.
//
// Under libFuzzer only the reader of each file's extension opens it (OpenImageIO's try_all_readers 0):
// with the default, every input those two readers refuse is offered to each of OpenImageIO's ~40 other
// readers in turn, which held the runs to about 100 executions a second while fuzzing their code, not
// the readers a session uses. The replay (replay_main.cc, no LLVMFuzzerInitialize) keeps the default.
#include <OpenImageIO/imageio.h>

#include "core/image_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  OIIO::attribute("try_all_readers", 0);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::MemoryFiles& files = ibrdf::fuzz::MemoryFiles::Get();
  for (const char* name : {"photo.dng", "photo.tif"}) {
    const std::string path = files.Put(name, data, size);
    ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] { ibrdf::ReadImageSpec(path); });
    ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] { ibrdf::ReadPhotoMetadata(path); });
  }
  return 0;
}
