// `ibrdf synth --material TABLE.binary` on the command line: --merl-lookup and --no-data as a user
// meets them (what is printed, what is written, what is refused).
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/merl_format.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/synth/holey_merl_table.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::HoleyMerlTable;
using testing::RunIbrdf;
using testing::ScratchDir;

const char kSmall[] = " --width 200 --height 150 --photos 4 --effects none";

TEST(SynthMerlCli, LinearLookupAndSkippedPixelsAreSaidAndRecorded) {
  ScratchDir dir;
  const std::string table = HoleyMerlTable(dir);
  const auto run = RunIbrdf("synth --out " + (dir / "s") + " --material " + table + " --merl-lookup linear" + kSmall,
                            /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("left out of the samples"), std::string::npos) << run.output;
  const nlohmann::json truth = ReadJsonFile(dir / "s/truth.json");
  EXPECT_EQ(truth.at("material").at("lookup"), "linear");
  EXPECT_EQ(truth.at("generator").at("material_no_data").at("policy"), "skip");
  EXPECT_GT(truth.at("generator").at("material_no_data").at("pixels").get<uint64_t>(), 0u);
  EXPECT_TRUE(std::filesystem::is_directory(dir / "s/masks"));
  // The samples are scored against the same (linear) lookups: a noise-free session agrees closely.
  const auto derender = RunIbrdf("derender " + (dir / "s") + " --out " + (dir / "s.npy"));
  ASSERT_EQ(derender.exit_code, 0) << derender.output;
  const auto compare = RunIbrdf("compare " + (dir / "s.npy") + " --out " + (dir / "c.json"));
  ASSERT_EQ(compare.exit_code, 0) << compare.output;
  const nlohmann::json figures = ReadJsonFile(dir / "c.json");
  for (int c = 0; c < 3; ++c) EXPECT_LT(figures.at("overall").at("median_rel_error")[c].get<double>(), 0.01);
}

TEST(SynthMerlCli, NoDataErrorAndLookupOnAModelAreRefused) {
  ScratchDir dir;
  const std::string table = HoleyMerlTable(dir);
  const auto refused = RunIbrdf("synth --out " + (dir / "e") + " --material " + table + " --no-data error" + kSmall);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("holey.binary"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("without data"), std::string::npos) << refused.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "e"));
  const auto model = RunIbrdf("synth --out " + (dir / "m") + " --material " + testing::MaterialPath("bluepaint") +
                              " --merl-lookup linear" + kSmall);
  EXPECT_NE(model.exit_code, 0);
  EXPECT_NE(model.output.find("MERL tables"), std::string::npos) << model.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "m"));
}

}  // namespace
}  // namespace ibrdf
