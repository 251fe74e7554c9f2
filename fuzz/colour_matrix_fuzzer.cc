// Fuzz target: a session's colour_chart block (the chart's photos, corners, the fitted colour matrix
// and its per-patch residuals that `ibrdf colour` writes), read by core/session.h Session::Load.
#include "fuzz/session_splice.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::LoadSpliced(data, size, "colour_chart.json", "colour_chart",
                           [](const nlohmann::json& file) { return file; });
  return 0;
}
