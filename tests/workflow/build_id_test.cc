// Tests of workflow/build_id.h: this test binary carries a GNU build-id note (linked with --build-id
// through ibrdf_workflow), other files have none, and the fallback hash tells files apart.
#include "workflow/build_id.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

TEST(BuildId, ThisBinaryHasAGnuBuildId) {
  const std::string id = ElfBuildId("/proc/self/exe");
  ASSERT_EQ(id.rfind("gnu-build-id:", 0), 0u) << id;
  EXPECT_GE(id.size(), std::string("gnu-build-id:").size() + 16);  // at least 8 bytes (sha1: 20)
  EXPECT_EQ(ExecutableBuildId(), id);
  EXPECT_EQ(ExecutableBuildId(), ExecutableBuildId());
  EXPECT_TRUE(std::filesystem::equivalent(ExecutablePath(), "/proc/self/exe"));
}

TEST(BuildId, OtherFilesHaveNoneAndHashApart) {
  ScratchDir dir;
  std::ofstream(dir / "a") << "not an ELF file, but long enough to hold an ELF header of 64 bytes ......";
  std::ofstream(dir / "b") << "not an ELF file, but long enough to hold an ELF header of 64 bytes .....!";
  std::ofstream(dir / "empty");
  EXPECT_EQ(ElfBuildId(dir / "a"), "");
  EXPECT_EQ(ElfBuildId(dir / "empty"), "");
  EXPECT_EQ(FileContentHash(dir / "a"), FileContentHash(dir / "a"));
  EXPECT_NE(FileContentHash(dir / "a"), FileContentHash(dir / "b"));
  EXPECT_EQ(FileContentHash(dir / "empty"), "fnv1a64:cbf29ce484222325");  // FNV-1a's offset basis
  EXPECT_THROW(ElfBuildId(dir / "missing"), Error);
  EXPECT_THROW(FileContentHash(dir / "missing"), Error);
}

}  // namespace
}  // namespace ibrdf
