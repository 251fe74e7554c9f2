// Fuzz target: workflow/batch_config.h ReadBatchConfig (`ibrdf batch CONFIG`), and the run command
// line of every entry it accepts. The folder holds a session folder s1/ and a recipe folder r1/ that
// a config may name or match with a pattern.
#include "fuzz/fuzz_input.h"
#include "workflow/batch_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ibrdf::fuzz::MemoryFiles& files = ibrdf::fuzz::MemoryFiles::Get();
  files.Fixture("s1/session.json", "{}");
  files.Fixture("r1/recipe.json", "{}");
  const std::string path = files.Put("batch.json", data, size);
  ibrdf::fuzz::ExpectCleanFailure(files.dir(), [&] {
    const ibrdf::BatchConfig config = ibrdf::ReadBatchConfig(path);
    for (const ibrdf::BatchEntry& entry : config.entries) ibrdf::RunArguments(entry);
  });
  return 0;
}
