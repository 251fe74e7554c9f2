#include "report/report_script.h"

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.h"
#include "core/file_util.h"
#include "core/subprocess.h"

#ifndef IBRDF_SOURCE_REPORT_SCRIPT
#define IBRDF_SOURCE_REPORT_SCRIPT "scripts/report.py"
#endif
#ifndef IBRDF_PYTHON
#define IBRDF_PYTHON "/usr/bin/python3"
#endif

namespace fs = std::filesystem;

namespace ibrdf {

ReportScriptSearch DefaultReportScriptSearch() {
  ReportScriptSearch search;
  if (const char* env = std::getenv("IBRDF_REPORT_SCRIPT")) search.environment = env;
  std::error_code error;
  const fs::path binary = fs::read_symlink("/proc/self/exe", error);
  if (!error) search.binary_path = binary.string();
  search.source_script = IBRDF_SOURCE_REPORT_SCRIPT;
  return search;
}

std::vector<std::string> ReportScriptCandidates(const ReportScriptSearch& search) {
  if (search.environment) return {*search.environment};
  std::vector<std::string> candidates;
  if (!search.binary_path.empty()) {
    const fs::path dir = fs::path(search.binary_path).parent_path();
    candidates.push_back((dir / ".." / "share" / "ibrdf" / "report.py").lexically_normal().string());
    candidates.push_back((dir / "report.py").lexically_normal().string());
  }
  if (!search.source_script.empty()) candidates.push_back(search.source_script);
  return candidates;
}

std::string FindReportScript(const ReportScriptSearch& search) {
  const std::vector<std::string> candidates = ReportScriptCandidates(search);
  if (search.environment) return candidates.front();
  std::string searched;
  for (const std::string& candidate : candidates) {
    if (fs::is_regular_file(candidate)) return candidate;
    searched += (searched.empty() ? "" : ", ") + candidate;
  }
  ThrowError("report.py", "the report's plotting script was not found (looked in: " + searched +
                              "; set IBRDF_REPORT_SCRIPT to its path)");
}

std::string ReportPython() { return IBRDF_PYTHON; }

namespace {

// Throws Error naming the script when it exited with `code` != 0 or wrote no index.html.
void CheckReportScript(const std::string& script, const std::string& out_dir, int code) {
  if (code != 0) {
    ThrowError(script, "the plotting script failed (exit " + std::to_string(code) +
                           "); its message is above (it needs Debian's python3-numpy and python3-matplotlib)");
  }
  RequireFile((fs::path(out_dir) / "index.html").string(), script + ": wrote no index.html");
}

}  // namespace

void RunReportScript(const std::string& python, const std::string& script, const std::string& run_dir,
                     const std::string& out_dir) {
  CheckReportScript(script, out_dir, RunSubprocess({python, script, fs::absolute(run_dir).string(), out_dir}));
}

BackgroundReportScript::BackgroundReportScript(const std::string& python, const std::string& script,
                                               const std::string& run_dir, const std::string& out_dir)
    : script_(script), out_dir_(out_dir) {
  std::vector<std::string> argv = {python, script, fs::absolute(run_dir).string(), out_dir, "--data-later"};
  thread_ = std::thread([this, argv] {
    try {
      code_ = RunSubprocess(argv);
    } catch (const std::exception&) {
      code_ = 127;  // fork failed
    }
  });
}

BackgroundReportScript::~BackgroundReportScript() {
  if (!thread_.joinable()) return;
  if (!finished_) std::ofstream((fs::path(out_dir_) / "report-abort").string()) << "the report failed\n";
  thread_.join();
}

void BackgroundReportScript::Finish() {
  IBRDF_CHECK(!finished_) << "BackgroundReportScript::Finish called twice";
  finished_ = true;
  thread_.join();
  CheckReportScript(script_, out_dir_, code_);
}

}  // namespace ibrdf
