// The installed layout: `cmake --install` puts the binary in bin/ and the report's plotting script in
// share/ibrdf/, and the installed `ibrdf report` runs the script from share/ibrdf/ (a stub put there in
// place of report.py), not the source tree's.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/sample_file.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

std::string RunCommand(const std::string& command, int* exit_code) {
  const testing::RunResult result = testing::RunShell(command + " 2>&1");
  *exit_code = result.exit_code;
  return result.output;
}

TEST(ReportInstall, TheInstalledBinaryRunsTheInstalledScript) {
  ScratchDir dir;
  const std::string prefix = dir / "prefix";
  int code = -1;
  std::string output = RunCommand(
      std::string("\"") + IBRDF_CMAKE_COMMAND + "\" --install \"" + IBRDF_BUILD_DIR + "\" --prefix \"" + prefix + "\"",
      &code);
  ASSERT_EQ(code, 0) << output;
  ASSERT_TRUE(fs::is_regular_file(prefix + "/bin/ibrdf")) << output;
  ASSERT_TRUE(fs::is_regular_file(prefix + "/share/ibrdf/report.py")) << output;

  // A stub in place of the installed script: it writes index.html and explorer.html and says where it ran
  // from.
  std::ofstream(prefix + "/share/ibrdf/report.py")
      << "import os, sys\n"
         "open(os.path.join(sys.argv[2], 'index.html'), 'w').write('<html></html>')\n"
         "open(os.path.join(sys.argv[2], 'explorer.html'), 'w').write('<html></html>')\n"
         "print('stub report.py of share/ibrdf ran')\n";
  // The smallest run folder: samples.npy alone (no sidecar, reconstruction or truth).
  const std::string run = dir / "run";
  fs::create_directories(run);
  BrdfSample sample{};
  sample.wi[2] = sample.wo[2] = 1.0f;
  WriteSamples(run + "/samples.npy", {sample, sample});
  ::unsetenv("IBRDF_REPORT_SCRIPT");
  output = RunCommand("\"" + prefix + "/bin/ibrdf\" -q report \"" + run + "\"", &code);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("stub report.py of share/ibrdf ran"), std::string::npos) << output;
  EXPECT_TRUE(fs::exists(run + "/report/index.html"));
  EXPECT_TRUE(fs::exists(run + "/report/report-data.json"));
}

}  // namespace
}  // namespace ibrdf
