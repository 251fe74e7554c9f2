// Helpers shared by the tests that need bundled materials and synthetic sessions.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "core/brdf_model.h"
#include "synth/synthetic.h"
#include "tests/scratch_dir.h"

namespace ibrdf::testing {

inline std::string SamplesDir() { return IBRDF_SAMPLES_DIR; }
inline std::string MaterialPath(const std::string& name) { return SamplesDir() + "/materials/" + name + ".json"; }

// Writes a synthetic session to `dir` and returns its manifest path.
inline std::string MakeSession(const std::string& dir, const SynthOptions& options, const BrdfModel& material) {
  const SynthSummary summary = WriteSyntheticSession(options, material, "test", dir, /*overwrite=*/true);
  EXPECT_TRUE(summary.success);
  return dir + "/session.json";
}

}  // namespace ibrdf::testing
