#include "workflow/temporaries.h"

#include <signal.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>

#include "core/logging.h"

namespace fs = std::filesystem;

namespace ibrdf {

std::vector<std::string> RemoveStaleTemporaries(const std::string& run_dir) {
  std::vector<fs::path> folders = {run_dir};
  for (const auto& entry : fs::directory_iterator(run_dir)) {
    if (entry.is_directory() && entry.path().filename().string()[0] != '.') folders.push_back(entry.path());
  }
  std::vector<std::string> removed;
  for (const fs::path& folder : folders) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      const size_t at = name.rfind(".tmp-");
      if (name.empty() || name[0] != '.' || at == std::string::npos) continue;
      const int pid = std::atoi(name.c_str() + at + 5);
      if (pid > 0 && (::kill(pid, 0) == 0 || errno != ESRCH)) continue;  // its writer still runs
      std::error_code ignored;
      fs::remove_all(entry.path(), ignored);
      removed.push_back(entry.path().string());
      Log(1, "removed the leftover of an interrupted stage: " + entry.path().string());
    }
  }
  return removed;
}

}  // namespace ibrdf
