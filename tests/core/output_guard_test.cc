// The output guard: an output is never an input nor a folder holding one, and replaces an existing
// file only when asked.
#include "core/output_guard.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

TEST(OutputGuard, RefusesInputsAndFoldersHoldingThem) {
  testing::ScratchDir dir;
  const std::string input = dir / "in/a.txt";
  fs::create_directories(dir / "in");
  std::ofstream(input) << "a";
  EXPECT_THROW(RequireWritableOutput(input, true, {input}), Error);
  EXPECT_THROW(RequireWritableOutput(dir / "in", true, {input}), Error);
  EXPECT_THROW(RequireWritableOutput(dir / "in/", true, {input}), Error);
  EXPECT_THROW(RequireOutputOutsideInputs(dir.str(), {input}), Error);
  EXPECT_THROW(RequireOutputOutsideInputs("", {}), Error);
  EXPECT_NO_THROW(RequireWritableOutput(dir / "out.txt", false, {input, "", dir / "missing"}));
}

TEST(OutputGuard, ReplacesOnlyWithOverwriteAndNeedsTheParent) {
  testing::ScratchDir dir;
  const std::string out = dir / "out.txt";
  std::ofstream(out) << "old";
  try {
    RequireWritableOutput(out, false, {});
    FAIL() << "an existing output without overwrite";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--overwrite"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(RequireWritableOutput(out, true, {}));
  EXPECT_THROW(RequireWritableOutput(dir / "no/such/folder/out.txt", true, {}), Error);
}

TEST(OutputGuard, FilesUnderListsEveryFileRecursively) {
  testing::ScratchDir dir;
  fs::create_directories(dir / "a/b");
  std::ofstream(dir / "a/one") << "1";
  std::ofstream(dir / "a/b/two") << "2";
  EXPECT_EQ(FilesUnder(dir / "a").size(), 2u);
  EXPECT_TRUE(FilesUnder(dir / "a/one").empty());  // a file is no folder
  EXPECT_TRUE(FilesUnder(dir / "none").empty());
}

}  // namespace
}  // namespace ibrdf
