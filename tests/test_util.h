// Helpers shared by the tests: scratch folders and synthetic sessions.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/brdf_model.h"
#include "derender/synthetic.h"

namespace ibrdf::testing {

// A fresh, empty scratch folder unique to the running test, removed when the object goes away.
class ScratchDir {
 public:
  ScratchDir() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("ibrdf-" + std::string(info->test_suite_name()) + "-" + info->name() + "-" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

inline std::string SamplesDir() { return IBRDF_SAMPLES_DIR; }
inline std::string MaterialPath(const std::string& name) { return SamplesDir() + "/materials/" + name + ".json"; }

// Writes a synthetic session to `dir` and returns its manifest path.
inline std::string MakeSession(const std::string& dir, const SynthOptions& options, const BrdfModel& material) {
  const SynthSummary summary = WriteSyntheticSession(options, material, "test", dir, /*overwrite=*/true);
  EXPECT_TRUE(summary.success);
  return dir + "/session.json";
}

}  // namespace ibrdf::testing
