// Tests of core/interruption.h: a process ended by SIGINT, SIGTERM or SIGHUP removes the temporaries
// its AtomicFile and AtomicDirectory objects hold, and still ends by that signal.
#include "core/interruption.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/file_util.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Listing(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  return names;
}

// Forks a child that opens a temporary folder and a temporary file in `folder`, writes into both and
// sends itself `signal_number`; returns its wait status.
int StatusOfChildStoppedBy(int signal_number, const std::string& folder) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    RemoveTemporariesOnInterrupt();
    AtomicDirectory directory(folder + "/rec", false);
    std::ofstream(directory.temporary_path() + "/brdf.json") << "{}";
    AtomicFile file(folder + "/samples.npy");
    std::ofstream(file.temporary_path()) << "partial";
    ::kill(::getpid(), signal_number);
    ::sleep(30);  // the cleanup ends the process long before
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

TEST(Interruption, SignalsRemoveTheTemporariesAndEndTheProcess) {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(signal_number);
    testing::ScratchDir dir;
    const int status = StatusOfChildStoppedBy(signal_number, dir.str());
    ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
    EXPECT_EQ(WTERMSIG(status), signal_number);
    EXPECT_TRUE(Listing(dir.str()).empty()) << "left: " << Listing(dir.str())[0];
  }
}

// Committed outputs are no temporaries: the signal leaves them.
TEST(Interruption, CommittedOutputsStay) {
  testing::ScratchDir dir;
  const pid_t pid = ::fork();
  if (pid == 0) {
    RemoveTemporariesOnInterrupt();
    AtomicFile file(dir / "done.json");
    std::ofstream(file.temporary_path()) << "{}";
    file.Commit();
    ::kill(::getpid(), SIGTERM);
    ::sleep(30);
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(Listing(dir.str()), std::vector<std::string>{"done.json"});
}

}  // namespace
}  // namespace ibrdf
