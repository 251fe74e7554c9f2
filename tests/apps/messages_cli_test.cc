// Usage and input errors from the command line read "ibrdf: error: ..." and name what is wrong in
// the user's terms: the stage and its flags, the file, never a raw library message.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/sample_file.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

void ExpectMessage(const std::string& arguments, int exit_code, const std::vector<std::string>& present,
                   const std::vector<std::string>& absent) {
  SCOPED_TRACE(arguments);
  const RunResult result = RunIbrdf(arguments);
  EXPECT_EQ(result.exit_code, exit_code) << result.output;
  EXPECT_EQ(result.output.rfind("ibrdf: error: ", 0), 0u) << result.output;
  for (const std::string& text : present) EXPECT_NE(result.output.find(text), std::string::npos) << result.output;
  for (const std::string& text : absent) EXPECT_EQ(result.output.find(text), std::string::npos) << result.output;
}

void WriteSmallSamples(const std::string& path) {
  BrdfSample s{};
  s.wi[2] = s.wo[2] = 1.0f;
  s.brdf[0] = s.brdf[1] = s.brdf[2] = 0.1f;
  WriteSamples(path, std::vector<BrdfSample>(8, s));
}

// `session init` on photos without poses writes its draft, lists what is missing and exits 2, with no
// second, meaningless line ("ibrdf: error: session: Runtime error").
TEST(MessagesCli, IncompleteSessionDraftEndsWithItsOwnWords) {
  ScratchDir dir;
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + std::string(IBRDF_SAMPLES_DIR) +
                                   "/materials/lambertian50.json --photos 2 --width 48 --height 36 --effects none");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const RunResult result = RunIbrdf("session init " + dir / "s/photos/000.exr" + " --out " + dir / "draft");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("incomplete: supply the missing items"), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("Runtime error"), std::string::npos) << result.output;
  EXPECT_TRUE(fs::exists(dir / "draft/session.draft.json")) << result.output;
}

TEST(MessagesCli, MissingRequiredFlagSaysIbrdfError) {
  ScratchDir dir;
  ExpectMessage("synth --out " + dir / "s", 2, {"synth: ", "--material or --material-map is required"}, {});
}

// CLI11 lists unexpected arguments last to first; the message gives them as typed, with the stage.
TEST(MessagesCli, UnexpectedArgumentsInTheOrderGivenWithTheStage) {
  ScratchDir dir;
  WriteSmallSamples(dir / "s.npy");
  ExpectMessage("reconstruct " + dir / "s.npy" + " --out " + dir / "r" + " --degre 1", 2,
                {"reconstruct: ", "--degre 1"}, {"1 --degre"});
  EXPECT_FALSE(fs::exists(dir / "r"));
}

// An option's constraint names the flag the user typed, not the options field behind it.
TEST(MessagesCli, OptionChecksNameTheFlag) {
  ScratchDir dir;
  ExpectMessage("derender " + dir / "none" + " --out " + dir / "x.npy" + " --stride 0", 2,
                {"derender: ", "--stride >= 1"}, {"pixel_stride"});
  ExpectMessage("derender " + dir / "none" + " --out " + dir / "x.npy" + " --max-theta-i-deg 95", 2,
                {"--max-theta-i-deg"}, {"max_theta_i_deg"});
}

// A symlink loop: the file named with the system's reason, not "filesystem error: status: ...".
TEST(MessagesCli, SymlinkLoopNamesThePath) {
  ScratchDir dir;
  fs::create_symlink(dir / "b", dir / "a");
  fs::create_symlink(dir / "a", dir / "b");
  ExpectMessage("derender " + dir / "a" + " --out " + dir / "x.npy", 1,
                {dir / "a", "Too many levels of symbolic links"}, {"filesystem error"});
  ExpectMessage("check " + dir / "a" + " --out " + dir / "c.json", 1, {dir / "a"}, {"filesystem error"});
}

// A sidecar whose `session` is a number is a wrongly typed key, not a missing one.
TEST(MessagesCli, NumericSidecarSessionIsNotMissing) {
  ScratchDir dir;
  WriteSmallSamples(dir / "s.npy");
  std::ofstream(SidecarPath(dir / "s.npy")) << "{\"session\": 5}\n";
  ExpectMessage("compare " + dir / "s.npy" + " --out " + dir / "c.json", 1,
                {"s.npy.json: /session", "expected the session's path (a string), got number"}, {"missing"});
}

}  // namespace
}  // namespace ibrdf
