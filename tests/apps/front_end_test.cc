// Tests of the front end (apps/main.cc) and the subcommand binaries' main (apps/command_main.cc): global
// flags anywhere on the command line, usage errors exit 2, no stage timer before an error line, and
// the light subcommands' binaries load none of the heavy libraries (start-up, docs/decisions.md).
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/version.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;
using testing::ScratchDir;

// Runs `ibrdf ARGUMENTS` with nothing added (RunIbrdf adds --silent or -q first).
RunResult RunRaw(const std::string& arguments) {
  return testing::RunShell(std::string(IBRDF_BINARY) + " " + arguments + " 2>&1");
}

std::string Binary(const std::string& name) { return (fs::path(IBRDF_BINARY).parent_path() / name).string(); }

// The shared libraries `ldd` lists for a binary.
std::string Ldd(const std::string& binary) { return testing::RunShell("ldd " + binary + " 2>&1").output; }

TEST(FrontEnd, VersionAndHelpListEverySubcommand) {
  const RunResult version = RunRaw("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find(kIbrdfVersionLine), std::string::npos) << version.output;
  const RunResult help = RunRaw("--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* name : {"synth", "scan", "align", "derender", "reconstruct", "check", "report", "run", "compare"}) {
    EXPECT_NE(help.output.find(std::string("  ") + name + " "), std::string::npos) << name << "\n" << help.output;
    EXPECT_TRUE(fs::is_regular_file(Binary(std::string("ibrdf-") + name))) << name;
  }
}

TEST(FrontEnd, GlobalFlagsAfterTheSubcommand) {
  ScratchDir dir;
  const std::string session = dir / "s";
  // -q after the subcommand's arguments: stage lines, no progress bars; --threads likewise.
  RunResult result = RunRaw("synth --out " + session + " --material " + std::string(IBRDF_SAMPLES_DIR) +
                            "/materials/lambertian50.json --photos 1 --width 80 --height 60 -q --threads 1");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("== synth"), std::string::npos) << result.output;
  result = RunRaw("derender " + session + " --out " + (dir / "a.npy") + " --silent");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "");  // --silent after the subcommand silences it
  result = RunRaw("--threads 1 derender " + session + " --out " + (dir / "b.npy") + " -q");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("-- derender: "), std::string::npos) << result.output;
}

TEST(FrontEnd, UsageErrorsExitTwo) {
  for (const char* arguments :
       {"", "--no-such-flag", "no-such-subcommand", "derender", "derender x --no-such-option y", "derender x --out",
        "check x --out y --theta-bin-deg abc", "--threads", "--threads -3 derender x --out y.npy", "run"}) {
    const RunResult result = RunRaw(arguments);
    EXPECT_EQ(result.exit_code, 2) << "ibrdf " << arguments << "\n" << result.output;
    EXPECT_FALSE(result.output.empty()) << arguments;
  }
}

TEST(FrontEnd, NoStageTimerBeforeAnError) {
  ScratchDir dir;
  const RunResult result = RunRaw("-q derender " + (dir / "missing") + " --out " + (dir / "x.npy"));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("ibrdf: error:"), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("-- derender"), std::string::npos) << result.output;
}

TEST(FrontEnd, LightSubcommandsLoadNoHeavyLibraries) {
  // The front end loads the C++ runtime only; check, reconstruct, compare and report no PCL, VTK,
  // OpenCV or CGAL-related libraries (GMP/MPFR); derender no VTK or OpenCV; run no stage library.
  const std::string front = Ldd(IBRDF_BINARY);
  for (const char* library : {"libpcl", "libvtk", "libopencv", "libembree", "libceres", "libOpenImageIO", "libtbb"}) {
    EXPECT_EQ(front.find(library), std::string::npos) << library << " in the front end:\n" << front;
  }
  for (const char* command : {"check", "reconstruct", "compare", "report", "run"}) {
    const std::string libraries = Ldd(Binary(std::string("ibrdf-") + command));
    for (const char* library : {"libpcl", "libvtk", "libopencv", "libembree", "libgmp", "libmpfr"}) {
      EXPECT_EQ(libraries.find(library), std::string::npos) << library << " in ibrdf-" << command;
    }
  }
  const std::string derender = Ldd(Binary("ibrdf-derender"));
  for (const char* library : {"libpcl", "libvtk", "libopencv", "libceres"}) {
    EXPECT_EQ(derender.find(library), std::string::npos) << library << " in ibrdf-derender:\n" << derender;
  }
}

}  // namespace
}  // namespace ibrdf
