// `ibrdf batch` end to end through Snakemake on local cores: six tiny synthetic sessions (different
// materials and shapes) and one broken session. The broken one fails alone with its error in the
// library's index; a second call re-runs only it; once fixed, it runs; then a call does nothing.
// Also `ibrdf library` on run folders, and the Slurm profile's dry run listing the jobs as sbatch
// would receive them. Skipped with a message where snakemake is not installed.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;

bool HaveSnakemake() { return std::system("snakemake --version > /dev/null 2>&1") == 0; }

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

nlohmann::json ReadJson(const std::string& path) { return nlohmann::json::parse(Slurp(path)); }

int64_t MTime(const std::string& path) { return fs::last_write_time(path).time_since_epoch().count(); }

// A tiny recipe: 6 photos of 160 x 120.
void WriteRecipe(const std::string& dir, const std::string& material, const std::string& shape_args) {
  fs::create_directories(dir);
  std::ofstream(dir + "/recipe.json") << "{\"format\": \"ibrdf-recipe\", \"version\": 1, \"name\": \""
                                      << fs::path(dir).filename().string() << "\", \"material\": \""
                                      << IBRDF_SAMPLES_DIR << "/materials/" << material << ".json\", \"synth\": ["
                                      << shape_args
                                      << ", \"--photos\", \"6\", \"--width\", \"160\", \"--height\", \"120\"]}";
}

// The six sessions and a broken one (a photo missing), and the config that lists them: recipes by a
// glob, the broken session by name.
std::string WriteBatch(const ScratchDir& dir) {
  WriteRecipe(dir / "recipes/bluepaint-sphere", "bluepaint", "\"--sample\", \"sphere\", \"--seed\", \"1\"");
  WriteRecipe(dir / "recipes/felt-sphere", "felt", "\"--sample\", \"sphere\", \"--seed\", \"2\"");
  WriteRecipe(dir / "recipes/primer-cylinder", "primer", "\"--sample\", \"cylinder\", \"--seed\", \"3\"");
  WriteRecipe(dir / "recipes/clay-cylinder", "clay",
              "\"--sample\", \"cylinder\", \"--radius-m\", \"0.03\", \"--seed\", \"4\"");
  WriteRecipe(dir / "recipes/glossy-sphere", "glossy-ggx",
              "\"--sample\", \"sphere\", \"--radius-m\", \"0.03\", \"--seed\", \"5\"");
  WriteRecipe(dir / "recipes/matte-sphere", "lambertian50",
              "\"--sample\", \"sphere\", \"--radius-m\", \"0.05\", \"--seed\", \"6\"");
  EXPECT_EQ(RunIbrdf(std::string("synth --material ") + IBRDF_SAMPLES_DIR +
                     "/materials/bluepaint.json --width 160 --height 120 --photos 4 --out " + dir / "broken")
                .exit_code,
            0);
  std::ofstream(dir / "batch.json") << R"({"format": "ibrdf-batch", "version": 1, "out": "out",
    "sessions": ["recipes/*", {"path": "broken", "name": "broken-session"}],
    "options": {"fits": false, "report": false},
    "compare": ["bluepaint-sphere", "felt-sphere", "glossy-sphere"]})";
  return dir / "batch.json";
}

std::map<std::string, nlohmann::json> ByName(const nlohmann::json& index) {
  std::map<std::string, nlohmann::json> result;
  for (const nlohmann::json& m : index.at("materials")) result[m.at("name").get<std::string>()] = m;
  return result;
}

TEST(BatchCommand, SixSessionsSucceedTheBrokenOneFailsAloneAndReRunsRetryOnlyIt) {
  if (!HaveSnakemake()) GTEST_SKIP() << "snakemake is not installed (scripts/install-deps installs it)";
  ScratchDir dir;
  const std::string config = WriteBatch(dir);
  const std::string photo = dir / "broken/photos/002.png";
  ASSERT_TRUE(fs::exists(photo)) << "synth's photo names changed; adapt the test";
  fs::rename(photo, dir / "002.png");

  const RunResult first = RunIbrdf("batch " + config + " --cores 2", true);
  EXPECT_EQ(first.exit_code, 1) << first.output;
  EXPECT_NE(first.output.find("1 of 7 sessions failed (broken-session)"), std::string::npos) << first.output;
  const std::string index_path = dir / "out/library/index.json";
  ASSERT_TRUE(fs::exists(index_path)) << first.output;
  std::map<std::string, nlohmann::json> index = ByName(ReadJson(index_path));
  ASSERT_EQ(index.size(), 7u);
  for (const auto& [name, m] : index) {
    if (name == "broken-session") continue;
    EXPECT_EQ(m.at("status"), "ok") << name << ": " << m.dump();
    const nlohmann::json& f = m.at("figures");
    EXPECT_GT(f.at("samples").get<int>(), 1000) << name;
    // Coverage counts measured and interpolated cells only (the honest table): a small session
    // of 8 photos covers 10 to 50 % of the table.
    EXPECT_GT(f.at("table_coverage").get<double>(), 0.05) << name;
    EXPECT_LE(f.at("table_coverage").get<double>(), 1.0) << name;
    EXPECT_TRUE(f.at("reciprocity").is_number()) << name;
    EXPECT_LT(f.at("samples_median_rel_error").get<double>(), 0.05) << name;
    EXPECT_TRUE(m.at("timings_s").at("stages_total").is_number()) << name;
    EXPECT_TRUE(fs::exists(dir / "out/library/" + m.at("files").at("merl").get<std::string>())) << name;
    EXPECT_TRUE(fs::exists(dir / "out/library/" + m.at("files").at("sphere").get<std::string>())) << name;
    EXPECT_NE(m.at("absent").dump().find("fits"), std::string::npos) << "run with fits: false";
  }
  const nlohmann::json& broken = index.at("broken-session");
  EXPECT_EQ(broken.at("status"), "failed");
  EXPECT_NE(broken.at("error").get<std::string>().find("photos/002.png"), std::string::npos) << broken.dump();
  EXPECT_NE(Slurp(dir / "out/logs/broken-session.log").find("photos/002.png"), std::string::npos);
  const std::string html = Slurp(dir / "out/library/index.html");
  EXPECT_NE(html.find("photos/002.png"), std::string::npos);
  EXPECT_NE(html.find("materials/felt-sphere/felt-sphere.sphere.png"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out/library/comparison.png"));
  EXPECT_EQ(ReadJson(index_path).at("comparison").at("materials").size(), 3u);

  // A second call re-runs the broken session only.
  const int64_t felt_log = MTime(dir / "out/logs/felt-sphere.log");
  const int64_t felt_summary = MTime(dir / "out/runs/felt-sphere/summary.json");
  const int64_t broken_log = MTime(dir / "out/logs/broken-session.log");
  const RunResult second = RunIbrdf("batch " + config + " --cores 2", true);
  EXPECT_EQ(second.exit_code, 1) << second.output;
  EXPECT_NE(second.output.find("broken-session: to run"), std::string::npos) << second.output;
  EXPECT_EQ(second.output.find("felt-sphere: to run"), std::string::npos) << second.output;
  EXPECT_EQ(MTime(dir / "out/logs/felt-sphere.log"), felt_log);
  EXPECT_EQ(MTime(dir / "out/runs/felt-sphere/summary.json"), felt_summary);
  EXPECT_NE(MTime(dir / "out/logs/broken-session.log"), broken_log);

  // Fixed, it runs; then a call does nothing at all.
  fs::rename(dir / "002.png", photo);
  const RunResult third = RunIbrdf("batch " + config + " --cores 2", true);
  EXPECT_EQ(third.exit_code, 0) << third.output;
  EXPECT_EQ(ByName(ReadJson(index_path)).at("broken-session").at("status"), "ok");
  const int64_t index_time = MTime(index_path);
  const int64_t broken_summary = MTime(dir / "out/runs/broken-session/summary.json");
  const RunResult fourth = RunIbrdf("batch " + config + " --cores 2", true);
  EXPECT_EQ(fourth.exit_code, 0) << fourth.output;
  EXPECT_NE(fourth.output.find("7 sessions, 0 to run"), std::string::npos) << fourth.output;
  EXPECT_EQ(MTime(index_path), index_time);
  EXPECT_EQ(MTime(dir / "out/runs/broken-session/summary.json"), broken_summary);
}

// The Slurm profile's dry run: one `measure` job per pending session with the resources sbatch gets.
TEST(BatchCommand, SlurmProfileDryRunListsTheJobsAsTheClusterReceivesThem) {
  if (!HaveSnakemake()) GTEST_SKIP() << "snakemake is not installed (scripts/install-deps installs it)";
  ScratchDir dir;
  WriteRecipe(dir / "a", "bluepaint", "\"--sample\", \"sphere\"");
  WriteRecipe(dir / "b", "felt", "\"--sample\", \"cylinder\"");
  std::ofstream(dir / "batch.json") << R"({"format": "ibrdf-batch", "version": 1, "out": "out",
    "sessions": ["a", "b"], "threads_per_job": 4, "mem_mb_per_job": 8000, "runtime_min_per_job": 30})";
  const RunResult dry = RunIbrdf("batch " + dir / "batch.json" + " --slurm --dry-run", true);
  ASSERT_EQ(dry.exit_code, 0) << dry.output;
  for (const std::string& expected : std::vector<std::string>{
           "rule measure:", "run " + fs::absolute(dir / "b").string(), "threads: 4", "mem_mb=8000", "runtime=30",
           "slurm_partition=main", "--threads 4 run " + fs::absolute(dir / "a").string(), "rule library:"}) {
    EXPECT_NE(dry.output.find(expected), std::string::npos) << "missing \"" << expected << "\" in\n" << dry.output;
  }
  EXPECT_FALSE(fs::exists(dir / "out/runs")) << "a dry run runs nothing";
}

TEST(BatchCommand, BadConfigIsOneLineNamingTheFieldAndNothingRuns) {
  ScratchDir dir;
  std::ofstream(dir / "batch.json") << R"({"format": "ibrdf-batch", "version": 1, "out": "out",
    "sessions": ["nothing-here-*"]})";
  RunResult bad = RunIbrdf("batch " + dir / "batch.json");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("/sessions/0: the pattern"), std::string::npos) << bad.output;
  std::ofstream(dir / "batch.json") << R"({"format": "ibrdf-batch", "version": 1, "out": "out",
    "sessions": ["."], "option": {}})";
  bad = RunIbrdf("batch " + dir / "batch.json");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("option"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace ibrdf
