// A valid version-2 session manifest with one block replaced by a fuzzed JSON file: the targets of
// blocks that other tools write for a session (the lights file of `ibrdf lights calibrate`, the colour
// chart's fitted matrix) are read by the session's reader inside a manifest that is otherwise valid,
// so that the fuzzer spends its executions in that block's parser.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/session.h"
#include "fuzz/fuzz_input.h"

namespace ibrdf::fuzz {

inline nlohmann::json SpliceSession() {
  return nlohmann::json::parse(R"({
    "format": "ibrdf-session", "version": 2, "name": "splice",
    "camera": {"model": "PINHOLE", "width": 32, "height": 24, "params": [40, 40, 16, 12]},
    "lights": [{"id": "L1", "kind": "directional", "direction": [0, 0, 1], "intensity": [1, 1, 1]}],
    "sample": {"kind": "sphere", "center": [0, 0, 0], "radius": 0.02},
    "photos": [{"file": "photos/000.png", "light": "L1", "exposure_s": 1,
                "camera_from_world": {"rotation": [1, 0, 0, 0], "translation": [0, 0, 0.5]}}]
  })");
}

// Reads the input as DIR/NAME (JSON) and, when it parses, loads the session with `key` set to the
// value `pick` takes from it.
template <typename Pick>
void LoadSpliced(const uint8_t* data, size_t size, const std::string& name, const std::string& key, Pick pick) {
  MemoryFiles& files = MemoryFiles::Get();
  // The manifest's photos and those a chart or lights file may name (the reader checks they exist).
  for (const char* photo : {"photos/000.png", "photos/001.png", "calibration/colour-chart.png"}) {
    files.Fixture(photo, "not read");
  }
  const std::string path = files.Put(name, data, size);
  ExpectCleanFailure(files.dir(), [&] {
    const nlohmann::json block = ReadJsonFile(path);
    nlohmann::json session = SpliceSession();
    session[key] = pick(block);
    Session::Load(files.Put("session.json", session.dump()));
  });
}

}  // namespace ibrdf::fuzz
