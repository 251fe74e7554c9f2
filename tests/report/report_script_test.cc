// Finding the report's plotting script (report/report_script.h): the environment wins, then the
// installed layout (bin/../share/ibrdf/report.py), then beside the binary (the build tree), then the
// source tree; nothing found is an error listing the places.
#include "report/report_script.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

void Touch(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << "# report.py\n";
}

TEST(ReportScript, LooksInTheDocumentedOrder) {
  ScratchDir dir;
  ReportScriptSearch search;
  search.binary_path = dir / "prefix/bin/ibrdf";
  search.source_script = dir / "source/scripts/report.py";
  const std::vector<std::string> candidates = ReportScriptCandidates(search);
  ASSERT_EQ(candidates.size(), 3u);
  EXPECT_EQ(candidates[0], dir / "prefix/share/ibrdf/report.py");
  EXPECT_EQ(candidates[1], dir / "prefix/bin/report.py");
  EXPECT_EQ(candidates[2], search.source_script);

  // Each place found once the ones before it are gone.
  Touch(search.source_script);
  EXPECT_EQ(FindReportScript(search), search.source_script);
  Touch(dir / "prefix/bin/report.py");
  EXPECT_EQ(FindReportScript(search), dir / "prefix/bin/report.py");
  Touch(dir / "prefix/share/ibrdf/report.py");
  EXPECT_EQ(FindReportScript(search), dir / "prefix/share/ibrdf/report.py");
  // The environment wins, even over files that exist.
  search.environment = dir / "elsewhere.py";
  EXPECT_EQ(ReportScriptCandidates(search), std::vector<std::string>{dir / "elsewhere.py"});
  EXPECT_EQ(FindReportScript(search), dir / "elsewhere.py");
}

TEST(ReportScript, NothingFoundListsThePlaces) {
  ScratchDir dir;
  ReportScriptSearch search;
  search.binary_path = dir / "bin/ibrdf";
  search.source_script = dir / "scripts/report.py";
  std::string message;
  try {
    FindReportScript(search);
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(dir / "share/ibrdf/report.py"), std::string::npos) << message;
  EXPECT_NE(message.find(dir / "bin/report.py"), std::string::npos) << message;
  EXPECT_NE(message.find(dir / "scripts/report.py"), std::string::npos) << message;
  EXPECT_NE(message.find("IBRDF_REPORT_SCRIPT"), std::string::npos) << message;
}

TEST(ReportScript, TheDefaultSearchStartsFromThisBinary) {
  const ReportScriptSearch search = DefaultReportScriptSearch();
  EXPECT_EQ(fs::path(search.binary_path).filename(), "report_script_test");
  EXPECT_FALSE(search.source_script.empty());
  EXPECT_EQ(fs::path(search.source_script).filename(), "report.py");
}

// A stand-in for report.py that records its arguments and keeps the --data-later protocol: it waits
// for OUT/report-data.json (then writes index.html) or OUT/report-abort (then notes it and exits 3).
constexpr char kProtocolStub[] =
    "import os, sys, time\n"
    "out = sys.argv[2]\n"
    "open(os.path.join(out, 'argv.txt'), 'w').write('\\n'.join(sys.argv[1:]))\n"
    "while not os.path.exists(os.path.join(out, 'report-data.json')):\n"
    "    if os.path.exists(os.path.join(out, 'report-abort')):\n"
    "        open(os.path.join(out, 'aborted'), 'w').close()\n"
    "        sys.exit(3)\n"
    "    time.sleep(0.01)\n"
    "open(os.path.join(out, 'index.html'), 'w').write('<html></html>')\n";

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool HavePython() { return fs::exists(ReportPython()); }

// The script starts before the data exists, is told it will come (--data-later, the run folder made
// absolute), waits for it, and Finish() returns once it wrote index.html.
TEST(BackgroundReportScript, StartsFirstAndFinishesOnceTheDataIsWritten) {
  if (!HavePython()) GTEST_SKIP() << ReportPython() << " is not installed";
  ScratchDir dir;
  const std::string script = dir / "stub.py", out = dir / "out";
  std::ofstream(script) << kProtocolStub;
  fs::create_directories(out);
  BackgroundReportScript plotting(ReportPython(), script, dir.str(), out);
  for (int i = 0; i < 500 && !fs::exists(out + "/argv.txt"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(fs::exists(out + "/argv.txt")) << "the script did not start";
  EXPECT_FALSE(fs::exists(out + "/index.html")) << "the script did not wait for report-data.json";
  std::ofstream(out + "/report-data.json") << "{}\n";
  plotting.Finish();
  EXPECT_TRUE(fs::exists(out + "/index.html"));
  EXPECT_EQ(ReadText(out + "/argv.txt"), fs::absolute(dir.str()).string() + "\n" + out + "\n--data-later");
  EXPECT_FALSE(fs::exists(out + "/report-abort"));
}

// Destroyed without Finish() (the C++ part failed), it tells the script to stop and waits for it.
TEST(BackgroundReportScript, WithoutFinishTheScriptIsToldToStop) {
  if (!HavePython()) GTEST_SKIP() << ReportPython() << " is not installed";
  ScratchDir dir;
  const std::string script = dir / "stub.py", out = dir / "out";
  std::ofstream(script) << kProtocolStub;
  fs::create_directories(out);
  { BackgroundReportScript plotting(ReportPython(), script, dir.str(), out); }
  EXPECT_TRUE(fs::exists(out + "/report-abort"));
  EXPECT_TRUE(fs::exists(out + "/aborted")) << "the script had not ended when the destructor returned";
  EXPECT_FALSE(fs::exists(out + "/index.html"));
}

// A script that fails is an error naming it, as with RunReportScript.
TEST(BackgroundReportScript, AFailingScriptIsAnErrorNamingIt) {
  if (!HavePython()) GTEST_SKIP() << ReportPython() << " is not installed";
  ScratchDir dir;
  const std::string script = dir / "failing.py", out = dir / "out";
  std::ofstream(script) << "import sys\nsys.exit(2)\n";
  fs::create_directories(out);
  BackgroundReportScript plotting(ReportPython(), script, dir.str(), out);
  std::ofstream(out + "/report-data.json") << "{}\n";
  std::string message;
  try {
    plotting.Finish();
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(script), std::string::npos) << message;
  EXPECT_NE(message.find("exit 2"), std::string::npos) << message;
}

// The real script, started early on a run folder `ibrdf report` refuses (a damaged samples.npy) and then
// told to stop, exits 3 without a word: the error is the C++ part's to report, not a Python traceback.
TEST(BackgroundReportScript, TheRealScriptStopsQuietlyOnAbort) {
  if (!HavePython()) GTEST_SKIP() << ReportPython() << " is not installed";
  ScratchDir dir;
  std::ofstream(dir / "samples.npy") << "not a .npy file";
  fs::create_directories(dir / "out");
  std::ofstream(dir / "out/report-abort") << "the report failed\n";
  const testing::RunResult result = testing::RunShell(ReportPython() + " " + FindReportScript() + " " + dir.str() +
                                                      " " + (dir / "out") + " --data-later 2>&1");
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_EQ(result.output, "");
  EXPECT_FALSE(fs::exists(dir / "out/index.html"));
}

}  // namespace
}  // namespace ibrdf
