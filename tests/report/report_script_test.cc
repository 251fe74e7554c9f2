// Finding the report's plotting script (report/report_script.h): the environment wins, then the
// installed layout (bin/../share/ibrdf/report.py), then beside the binary (the build tree), then the
// source tree; nothing found is an error listing the places.
#include "report/report_script.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
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

}  // namespace
}  // namespace ibrdf
