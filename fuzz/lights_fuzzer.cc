// Fuzz target: the lights file of `ibrdf lights calibrate` ({"format": "ibrdf-lights", "lights": [...]}),
// whose `lights` array is the session format's: read by core/session.h Session::Load with the file's
// `lights` (or, when it has none, the whole file) as the manifest's lights.
#include "fuzz/session_splice.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::LoadSpliced(data, size, "lights.json", "lights", [](const nlohmann::json& file) {
    return file.is_object() && file.contains("lights") ? file["lights"] : file;
  });
  return 0;
}
