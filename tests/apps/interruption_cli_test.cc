// A stage stopped by SIGINT or SIGTERM while it writes leaves no hidden temporary beside its output
// (core/interruption.h), and ends by that signal.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/sample_file.h"
#include "tests/scratch_dir.h"

extern char** environ;

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

// The hidden temporaries in `folder`.
std::vector<std::string> Temporaries(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name[0] == '.' && name.find(".tmp-") != std::string::npos) names.push_back(name);
  }
  return names;
}

// Samples of a Lambertian over the hemisphere, enough for reconstruct to run a while.
void WriteLambertianSamples(const std::string& path) {
  std::vector<BrdfSample> samples;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      BrdfSample s{};
      const double ti = 1.4 * i / 40, pi = 6.28 * j / 40;
      s.wi[0] = std::sin(ti) * std::cos(pi), s.wi[1] = std::sin(ti) * std::sin(pi), s.wi[2] = std::cos(ti);
      s.wo[0] = -std::sin(0.3 + ti / 2), s.wo[1] = 0.0f, s.wo[2] = std::cos(0.3 + ti / 2);
      s.brdf[0] = s.brdf[1] = s.brdf[2] = 0.15f;
      samples.push_back(s);
    }
  }
  WriteSamples(path, samples);
}

// Starts `ibrdf reconstruct`, sends `signal_number` as soon as its temporary folder appears, and
// expects the process to end by the signal with nothing hidden left.
void ExpectCleanStop(int signal_number) {
  SCOPED_TRACE(signal_number);
  testing::ScratchDir dir;
  WriteLambertianSamples(dir / "samples.npy");
  const std::string samples = dir / "samples.npy", out = dir / "rec";
  std::vector<std::string> args = {IBRDF_BINARY, "--silent", "reconstruct", samples, "--out", out};
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ), 0);
  bool signalled = false;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (!signalled && !Temporaries(dir.str()).empty()) {
      ::kill(pid, signal_number);
      signalled = true;
    }
    if (std::chrono::steady_clock::now() - start > std::chrono::seconds(120)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      FAIL() << "reconstruct did not end";
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_TRUE(signalled) << "reconstruct ended before its temporary was seen (status " << status << ")";
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), signal_number);
  const std::vector<std::string> left = Temporaries(dir.str());
  EXPECT_TRUE(left.empty()) << "left behind: " << left[0];
  EXPECT_FALSE(fs::exists(out));
}

TEST(InterruptionCli, ReconstructStoppedBySigintLeavesNoTemporary) { ExpectCleanStop(SIGINT); }

TEST(InterruptionCli, ReconstructStoppedBySigtermLeavesNoTemporary) { ExpectCleanStop(SIGTERM); }

// `ibrdf derender` streams each photo's samples into its temporary file: stopped by SIGTERM once rows
// are in it (the file has grown past its header), it ends by the signal and leaves neither the sample
// file, nor its sidecar, nor the temporary.
TEST(InterruptionCli, DerenderStoppedWhileStreamingLeavesNoFile) {
  testing::ScratchDir dir;
  const std::string session = dir / "session", out_dir = dir / "out", out = dir / "out/samples.npy";
  const std::string synth = std::string(IBRDF_BINARY) + " --silent synth --out " + session + " --material " +
                            IBRDF_SAMPLES_DIR + "/materials/bluepaint.json --photos 30 --width 480 --height 360";
  ASSERT_EQ(std::system(synth.c_str()), 0) << synth;
  fs::create_directories(out_dir);
  std::vector<std::string> args = {IBRDF_BINARY, "--silent", "--threads", "1", "derender", session, "--out", out};
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ), 0);
  bool signalled = false;
  uintmax_t seen_bytes = 0;
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (!signalled) {
      for (const std::string& name : Temporaries(out_dir)) {
        std::error_code ignored;
        const uintmax_t bytes = fs::file_size(fs::path(out_dir) / name, ignored);
        if (name.find("samples") != std::string::npos && bytes != uintmax_t(-1) && bytes > 4096) {
          seen_bytes = bytes;
          ::kill(pid, SIGTERM);
          signalled = true;
        }
      }
    }
    if (std::chrono::steady_clock::now() - start > std::chrono::seconds(120)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      FAIL() << "derender did not end";
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_TRUE(signalled) << "derender ended before rows were seen in its temporary (status " << status << ")";
  EXPECT_GT(seen_bytes, 4096u);
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(fs::is_empty(out_dir)) << "files left in " << out_dir;
}

}  // namespace
}  // namespace ibrdf
