// Fuzz target: core/session.h Session::Load of a session.json (photos it names do not exist, so a
// well-formed manifest ends in an error naming the photo).
#include "core/session.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string dir = ibrdf::fuzz::ScratchDir();
  const std::string path = ibrdf::fuzz::PutFile("session.json", data, size);
  ibrdf::fuzz::ExpectCleanFailure(dir, [&] { ibrdf::Session::Load(path); });
  return 0;
}
