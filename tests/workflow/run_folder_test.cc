// The run folder: claimed for one input; another input's run is refused, or emptied with overwrite.
#include "workflow/run_folder.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

TEST(RunFolder, ClaimedForOneInput) {
  testing::ScratchDir dir;
  const std::string out = dir / "run";
  EXPECT_EQ(RunFolderInput(out), "");
  ClaimRunFolder(out, "/data/a", false);
  EXPECT_EQ(RunFolderInput(out), "/data/a");
  std::ofstream(out + "/samples.npy") << "a's";
  ClaimRunFolder(out, "/data/a", false);  // the same input: resumed, nothing removed
  EXPECT_TRUE(fs::exists(out + "/samples.npy"));
  try {
    ClaimRunFolder(out, "/data/b", false);
    FAIL() << "another input's run folder";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/data/a"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(out + "/samples.npy"));
  ClaimRunFolder(out, "/data/b", true);  // emptied first
  EXPECT_FALSE(fs::exists(out + "/samples.npy"));
  EXPECT_EQ(RunFolderInput(out), "/data/b");
}

TEST(RunFolder, RefusesAnOutputThatHoldsTheInput) {
  testing::ScratchDir dir;
  fs::create_directories(dir / "session");
  EXPECT_THROW(RunInFolder(dir / "session", dir.str(), MeasurementOptions(), false, ChildStageLauncher(1), "ibrdf test",
                           Timer()),
               Error);
}

}  // namespace
}  // namespace ibrdf
