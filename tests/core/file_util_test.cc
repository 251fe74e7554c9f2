// Tests of core/file_util.h: outputs appear only when complete, and a stage never replaces an existing
// folder unless asked to.
#include "core/file_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A fresh folder per test.
class FileUtilTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = scratch_.str(); }
  testing::ScratchDir scratch_;

  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  // The names in `folder` (default: the test folder), hidden files included.
  std::vector<std::string> Listing(const std::string& folder = "") const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder.empty() ? dir_ : folder)) {
      names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
  }

  std::string dir_;
};

// Without Commit (an exception while writing) neither the temporary nor the final file remains.
TEST_F(FileUtilTest, AtomicFileWithoutCommitLeavesNothing) {
  {
    AtomicFile file(Path("result.json"));
    std::ofstream(file.temporary_path()) << "half written";
    EXPECT_TRUE(fs::exists(file.temporary_path()));
  }
  EXPECT_TRUE(Listing().empty());
  try {
    AtomicFile file(Path("result.json"));
    std::ofstream(file.temporary_path()) << "half written";
    throw std::runtime_error("writer failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(Listing().empty());
}

// An existing file survives an aborted rewrite unchanged.
TEST_F(FileUtilTest, AtomicFileWithoutCommitKeepsOldFile) {
  std::ofstream(Path("result.json")) << "old";
  {
    AtomicFile file(Path("result.json"));
    std::ofstream(file.temporary_path()) << "new";
  }
  EXPECT_EQ(ReadText(Path("result.json")), "old");
  EXPECT_EQ(Listing(), std::vector<std::string>{"result.json"});
}

// Commit moves the temporary into place (replacing any old file) and leaves nothing else.
TEST_F(FileUtilTest, AtomicFileCommitPublishes) {
  std::ofstream(Path("result.json")) << "old";
  {
    AtomicFile file(Path("result.json"));
    EXPECT_EQ(file.final_path(), Path("result.json"));
    EXPECT_NE(file.temporary_path(), file.final_path());
    std::ofstream(file.temporary_path()) << "new";
    EXPECT_EQ(ReadText(Path("result.json")), "old");  // not visible before Commit
    file.Commit();
  }
  EXPECT_EQ(ReadText(Path("result.json")), "new");
  EXPECT_EQ(Listing(), std::vector<std::string>{"result.json"});
}

// The temporary lies beside the final file and keeps its extension (OpenImageIO picks the writer by it).
TEST_F(FileUtilTest, AtomicFileTemporaryKeepsFolderAndExtension) {
  AtomicFile a(Path("photo.exr")), b(Path("photo.exr"));
  EXPECT_EQ(fs::path(a.temporary_path()).parent_path(), fs::path(dir_));
  EXPECT_EQ(fs::path(a.temporary_path()).extension(), ".exr");
  EXPECT_NE(a.temporary_path(), b.temporary_path());  // two writers do not collide
}

TEST_F(FileUtilTest, AtomicFileInMissingFolderIsAnError) {
  const std::string path = Path("no_such_folder/result.json");
  try {
    AtomicFile file(path);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// An existing folder is refused without replace_existing; its contents are untouched.
TEST_F(FileUtilTest, AtomicDirectoryRefusesExistingWithoutFlag) {
  fs::create_directories(Path("out"));
  std::ofstream(Path("out/old.txt")) << "old";
  try {
    AtomicDirectory folder(Path("out"), false);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(Path("out")), std::string::npos) << e.what();
  }
  // A trailing slash names the same folder.
  EXPECT_THROW(AtomicDirectory(Path("out") + "/", false), Error);
  EXPECT_EQ(ReadText(Path("out/old.txt")), "old");
  EXPECT_EQ(Listing(), std::vector<std::string>{"out"});
}

// With replace_existing, Commit swaps in the new folder; the old contents are gone and no temporary
// or set-aside folder remains.
TEST_F(FileUtilTest, AtomicDirectoryReplacesExistingWithFlag) {
  fs::create_directories(Path("out"));
  std::ofstream(Path("out/old.txt")) << "old";
  {
    AtomicDirectory folder(Path("out"), true);
    std::ofstream(fs::path(folder.temporary_path()) / "new.txt") << "new";
    EXPECT_TRUE(fs::exists(Path("out/old.txt")));  // untouched until Commit
    folder.Commit();
  }
  EXPECT_EQ(Listing(Path("out")), std::vector<std::string>{"new.txt"});
  EXPECT_EQ(ReadText(Path("out/new.txt")), "new");
  EXPECT_EQ(Listing(), std::vector<std::string>{"out"});
}

// Without Commit the temporary folder is removed, and an existing folder stays as it was.
TEST_F(FileUtilTest, AtomicDirectoryWithoutCommitLeavesNothing) {
  {
    AtomicDirectory folder(Path("fresh"), false);
    EXPECT_TRUE(fs::is_directory(folder.temporary_path()));
    std::ofstream(fs::path(folder.temporary_path()) / "partial.txt") << "partial";
  }
  EXPECT_TRUE(Listing().empty());

  fs::create_directories(Path("out"));
  std::ofstream(Path("out/old.txt")) << "old";
  {
    AtomicDirectory folder(Path("out"), true);
    std::ofstream(fs::path(folder.temporary_path()) / "new.txt") << "new";
  }
  EXPECT_EQ(Listing(Path("out")), std::vector<std::string>{"old.txt"});
  EXPECT_EQ(Listing(), std::vector<std::string>{"out"});
}

// A new folder is created by Commit.
TEST_F(FileUtilTest, AtomicDirectoryCreatesNewFolder) {
  {
    AtomicDirectory folder(Path("fresh"), false);
    std::ofstream(fs::path(folder.temporary_path()) / "a.txt") << "a";
    EXPECT_FALSE(fs::exists(Path("fresh")));
    folder.Commit();
  }
  EXPECT_EQ(Listing(Path("fresh")), std::vector<std::string>{"a.txt"});
  EXPECT_EQ(Listing(), std::vector<std::string>{"fresh"});
}

TEST_F(FileUtilTest, RequireFile) {
  std::ofstream(Path("present.txt")) << "x";
  EXPECT_NO_THROW(RequireFile(Path("present.txt"), "input"));
  try {
    RequireFile(Path("absent.txt"), "photo");
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(Path("absent.txt")), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("photo"), std::string::npos) << e.what();
  }
  EXPECT_THROW(RequireFile(dir_, "photo"), Error);  // a folder is not a file
}

TEST(ResolvePath, RelativeJoinsAbsoluteStays) {
  EXPECT_EQ(ResolvePath("/data/session", "photos/a.png"), "/data/session/photos/a.png");
  EXPECT_EQ(ResolvePath("/data/session", "../other/b.png"), "/data/other/b.png");
  EXPECT_EQ(ResolvePath("/data/session", "/abs/c.png"), "/abs/c.png");
  EXPECT_EQ(ResolvePath("session", "./d.png"), "session/d.png");
  EXPECT_EQ(ResolvePath("/data/session", ""), "");
}

TEST_F(FileUtilTest, SameFile) {
  std::ofstream(Path("a.txt")) << "a";
  std::ofstream(Path("b.txt")) << "b";
  EXPECT_TRUE(SameFile(Path("a.txt"), Path("a.txt")));
  EXPECT_TRUE(SameFile(Path("a.txt"), dir_ + "/./a.txt"));
  EXPECT_FALSE(SameFile(Path("a.txt"), Path("b.txt")));
  EXPECT_TRUE(SameFile(Path("new.txt"), dir_ + "/x/../new.txt"));  // neither exists yet
  EXPECT_FALSE(SameFile(Path("new.txt"), Path("other.txt")));
}

// A killed writer's temporaries (".NAME.tmp-PID-N") must not wait for `ibrdf run` to clean them:
// the next writer of the same output removes them, and keeps those of live processes.
TEST_F(FileUtilTest, StaleTemporariesAreRemovedByTheNextWriter) {
  // A process id that no longer exists: a child that has exited and been reaped.
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  waitpid(child, &status, 0);
  const std::string dead = std::to_string(child), live = std::to_string(getpid());
  fs::create_directories(Path(".rec.tmp-" + dead + "-3/sub"));
  fs::create_directories(Path(".rec.tmp-" + live + "-9"));
  std::ofstream(Path(".samples.tmp-" + dead + "-1.npy")) << "x";
  std::ofstream(Path(".other.tmp-" + dead + "-1.npy")) << "x";
  {
    AtomicDirectory directory(Path("rec"), false);
    AtomicFile file(Path("samples.npy"));
  }
  EXPECT_EQ(Listing(), (std::vector<std::string>{".other.tmp-" + dead + "-1.npy", ".rec.tmp-" + live + "-9"}));
}

// Renaming the samples and their sidecar separately, a writer stopped in between would leave a new file
// beside the previous run's sidecar. CommitWithManifest removes the old manifest first and moves the
// new one last: a failure between leaves the data without a manifest, never paired with the old one.
TEST_F(FileUtilTest, CommitWithManifestNeverPairsNewDataWithOldManifest) {
  std::ofstream(Path("data")) << "old";
  std::ofstream(Path("data.json")) << "old";
  {
    AtomicFile data(Path("data")), manifest(Path("data.json"));
    std::ofstream(manifest.temporary_path()) << "new";
    // The data's temporary is missing: its rename fails after the old manifest was removed.
    EXPECT_THROW(CommitWithManifest(&data, &manifest), Error);
  }
  EXPECT_EQ(ReadText(Path("data")), "old");
  EXPECT_FALSE(fs::exists(Path("data.json")));
  std::ofstream(Path("data.json")) << "old";
  AtomicFile data(Path("data")), manifest(Path("data.json"));
  std::ofstream(data.temporary_path()) << "new";
  std::ofstream(manifest.temporary_path()) << "new";
  CommitWithManifest(&data, &manifest);
  EXPECT_EQ(ReadText(Path("data")), "new");
  EXPECT_EQ(ReadText(Path("data.json")), "new");
  EXPECT_EQ(Listing(), (std::vector<std::string>{"data", "data.json"}));
}

}  // namespace
}  // namespace ibrdf
