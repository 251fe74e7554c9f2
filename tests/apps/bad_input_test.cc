// The crash, hang and silent-acceptance cases the fuzzers found, through the command line, each with the
// failing input: a non-zero exit, one line naming the file (and field) and what is wrong, no output.
#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/npy.h"
#include "core/sample_file.h"
#include "tests/run_ibrdf.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

// A non-zero exit (not a crash: 1, the tool's error exit) with one line naming `file`.
void ExpectCleanError(const RunResult& result, const std::string& file, const std::string& what) {
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find(file), std::string::npos) << result.output;
  EXPECT_NE(result.output.find(what), std::string::npos) << what << ": " << result.output;
  EXPECT_LE(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

class BadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    samples_ = dir_ / "samples.npy";
    BrdfSample s{};
    s.wi[2] = s.wo[2] = 1.0f;
    s.brdf[0] = s.brdf[1] = s.brdf[2] = 0.1f;
    WriteSamples(samples_, std::vector<BrdfSample>(50, s));
  }
  ScratchDir dir_;
  std::string samples_;
};

// Was a segfault (heap overflow under ASan): the shape's element count overflowed.
TEST_F(BadInputTest, ReconstructEvalShapeOverflow) {
  const std::string eval = dir_ / "eval.npy";
  std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (6148914691236517206, 3), }";
  dict.append(64 - (10 + dict.size() + 1) % 64, ' ');
  dict.push_back('\n');
  std::ofstream(eval, std::ios::binary) << std::string("\x93NUMPY\x01\x00", 8) << char(dict.size() & 0xff)
                                        << char(dict.size() >> 8) << dict << std::string(16, '\0');
  const RunResult result = RunIbrdf("reconstruct " + samples_ + " --eval " + eval + " --out " + dir_ / "rec");
  ExpectCleanError(result, eval, "overflows");
  EXPECT_FALSE(fs::exists(dir_ / "rec"));
}

// Were answered with finite values.
TEST_F(BadInputTest, ReconstructEvalNanAndOutOfRangePoints) {
  const std::string eval = dir_ / "eval.npy";
  WriteNpyArray(eval, std::vector<double>{0.1, 0.2, std::nan("")}, {1, 3});
  ExpectCleanError(RunIbrdf("reconstruct " + samples_ + " --eval " + eval + " --out " + dir_ / "rec"), eval,
                   "not finite");
  WriteNpyArray(eval, std::vector<double>{0.1, 0.2, 0.3, 0.1, 2.0, 0.3}, {2, 3});
  ExpectCleanError(RunIbrdf("reconstruct " + samples_ + " --eval " + eval + " --out " + dir_ / "rec"), eval, "row 1");
  EXPECT_FALSE(fs::exists(dir_ / "rec"));
}

// Hung or grew to gigabytes: a FIFO or /dev/zero as --truth, --material or the samples.
TEST_F(BadInputTest, NonRegularFilesAreRefused) {
  const std::string fifo = dir_ / "fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ExpectCleanError(RunIbrdf("compare " + samples_ + " --truth /dev/zero"), "/dev/zero", "not a regular file");
  ExpectCleanError(RunIbrdf("compare " + samples_ + " --truth " + fifo), fifo, "not a regular file");
  ExpectCleanError(RunIbrdf("reconstruct " + samples_ + " --truth " + fifo + " --out " + dir_ / "rec"), fifo,
                   "not a regular file");
  ExpectCleanError(RunIbrdf("check /dev/zero --out " + dir_ / "c.json"), "/dev/zero", "not a regular file");
}

// NaN in a sample file reached `check` (null, -nan) and `compare` ("B nan %").
TEST_F(BadInputTest, NanSamplesAreRefusedByCheckAndCompare) {
  BrdfSample s{};
  s.wi[2] = s.wo[2] = 1.0f;
  s.brdf[2] = std::numeric_limits<float>::quiet_NaN();
  WriteSamples(samples_, std::vector<BrdfSample>(5, s));
  ExpectCleanError(RunIbrdf("check " + samples_ + " --out " + dir_ / "c.json"), samples_, "sample 0: brdf[2]");
  EXPECT_FALSE(fs::exists(dir_ / "c.json"));
  const std::string truth = dir_ / "truth.json";
  std::ofstream(truth) << nlohmann::json{{"format", "ibrdf-truth"},
                                         {"version", 1},
                                         {"generator", nlohmann::json::object()},
                                         {"material", {{"model", "lambertian"}, {"albedo", {0.5, 0.5, 0.5}}}}};
  ExpectCleanError(RunIbrdf("compare " + samples_ + " --truth " + truth), samples_, "sample 0: brdf[2]");
}

// A number JSON cannot hold, and a key given twice, in the material: one line naming file and field.
TEST_F(BadInputTest, MaterialJsonErrors) {
  const std::string material = dir_ / "m.json";
  std::ofstream(material) << "{\"model\": \"lambertian\", \"albedo\": [1e400, 0.5, 0.5]}";
  ExpectCleanError(RunIbrdf("synth --material " + material + " --out " + dir_ / "s"), material, "invalid JSON");
  std::ofstream(material) << "{\"model\": \"lambertian\", \"albedo\": [0.5, 0.5, 0.5], \"albedo\": [1, 1, 1]}";
  ExpectCleanError(RunIbrdf("synth --material " + material + " --out " + dir_ / "s"), material, "/albedo");
  std::ofstream(material) << nlohmann::json{
      {"model", "lafortune"},
      {"diffuse", {0.1, 0.1, 0.1}},
      {"lobes", {{{"Cxy", {-1, -1, -1}}, {"Cz", {1e300, 1, 1}}, {"n", {10, 10, 10}}}}}};
  ExpectCleanError(RunIbrdf("synth --material " + material + " --out " + dir_ / "s"), material, "/lobes/0/Cz");
  EXPECT_FALSE(fs::exists(dir_ / "s"));
}

// Every photo saturated: was exit 0 with 0 samples.
TEST_F(BadInputTest, DerenderWithNoUsablePixelIsAnError) {
  const std::string session = dir_ / "session";
  const RunResult synth = RunIbrdf("synth --out " + session + " --material " + MaterialPath("lambertian50") +
                                   " --photos 2 --width 48 --height 36 --effects none");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  nlohmann::json manifest;
  std::ifstream(session + "/session.json") >> manifest;
  manifest["radiometry"]["saturation_level"] = 1e-9;
  std::ofstream(session + "/session.json") << manifest.dump(2);
  const RunResult result = RunIbrdf("derender " + session + " --out " + dir_ / "d.npy");
  ExpectCleanError(result, session, "no BRDF samples");
  EXPECT_FALSE(fs::exists(dir_ / "d.npy"));
  EXPECT_FALSE(fs::exists(dir_ / "d.npy.json"));
}

// A run-folder stamp nested 10^5 deep overflowed the stack; now the stage is re-run as unreadable.
TEST_F(BadInputTest, RunWithADeeplyNestedStamp) {
  const std::string session = dir_ / "session";
  ASSERT_EQ(RunIbrdf("synth --out " + session + " --material " + MaterialPath("lambertian50") +
                     " --photos 2 --width 48 --height 36 --effects none")
                .exit_code,
            0);
  const std::string run = dir_ / "run";
  RunResult result = RunIbrdf("run " + session + " --out " + run + " --stop-after derender");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ASSERT_TRUE(fs::exists(run + "/stamps/derender.json"));
  std::ofstream(run + "/stamps/derender.json") << std::string(100000, '[') << std::string(100000, ']');
  result = RunIbrdf("run " + session + " --out " + run + " --stop-after derender", true);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("unreadable"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace ibrdf
