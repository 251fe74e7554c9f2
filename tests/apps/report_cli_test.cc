// The command-line rough edges of `check`, `report` and `run`, each through the tool
// as a user types it: check's regression line says "invalid" rather than "0.00 % over 0 pairs"; help
// texts without CLI11's "{false}"; unit-suffixed option names with the old names as aliases; `report`
// finds the reconstruction it is given; a report titled from the run rather than "synth"; `run`
// refuses a folder holding another input's run unless --overwrite; `run` passes stage options through.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/sample_file.h"
#include "reconstruct/consistency.h"
#include "reconstruct/prediction_check.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;

const std::string kSynth = std::string("synth --material ") + IBRDF_SAMPLES_DIR +
                           "/materials/bluepaint.json --width 160 --height 120 --photos 6 --out ";

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

TEST(ReportCli, RegressionLineSaysInvalidNotZeroPercent) {
  const PredictionReport empty;  // no pairs, no held-out photos: every figure invalid
  const std::string line = RegressionSummary(empty);
  EXPECT_NE(line.find("reciprocity near the incidence plane invalid"), std::string::npos) << line;
  EXPECT_NE(line.find("bilateral symmetry invalid"), std::string::npos) << line;
  EXPECT_EQ(line.find("0.00 %"), std::string::npos) << line;
  EXPECT_EQ(line.find("over 0 pairs"), std::string::npos) << line;
}

// Every subcommand's help: no CLI11 default braces on a flag ("--no-mixed-pixel-mask{false}").
TEST(ReportCli, HelpTextsHaveNoDefaultBracesOnFlags) {
  for (const char* command : {"targets", "session init", "synth", "scan", "align", "lights calibrate", "lights synth",
                              "derender", "reconstruct", "check", "report", "run", "compare", "batch", "library"}) {
    const RunResult help = RunIbrdf(std::string(command) + " --help");
    EXPECT_EQ(help.exit_code, 0) << command;
    EXPECT_EQ(help.output.find("{false}"), std::string::npos) << command << ":\n" << help.output;
    EXPECT_EQ(help.output.find("{true}"), std::string::npos) << command << ":\n" << help.output;
  }
  EXPECT_NE(RunIbrdf("derender --help").output.find("--no-mixed-pixel-mask "), std::string::npos);
  const RunResult report = RunIbrdf("report --help");
  for (const char* name : {"--render-size-px", "--angles-deg", "--reconstruction", "--title"}) {
    EXPECT_NE(report.output.find(name), std::string::npos) << name;
  }
  const RunResult check = RunIbrdf("check --help");
  EXPECT_NE(check.output.find("--min-pairs"), std::string::npos);
  EXPECT_EQ(check.output.find("isotropy"), std::string::npos) << "one name: bilateral symmetry";
}

// Option names carry their unit; the previous release's names still work for one release, hidden from
// --help, with a warning naming the new name; giving both is a usage error.
TEST(ReportCli, UnitSuffixedNamesWithHiddenOldAliases) {
  const struct {
    const char* command;
    std::vector<std::string> renamed;  // old name, new name, ...
  } commands[] = {
      {"synth",
       {"--radius", "--radius-m", "--length", "--length-m", "--camera-distance", "--camera-distance-m",
        "--light-distance", "--light-distance-m", "--origin", "--origin-m", "--full-well", "--full-well-e",
        "--read-noise", "--read-noise-e"}},
      {"session init",
       {"--sample-radius", "--sample-radius-m", "--sample-center", "--sample-center-m", "--light-position",
        "--light-position-m"}},
      {"lights synth",
       {"--light-distance", "--light-distance-m", "--center", "--center-m", "--radius", "--radius-m", "--distance",
        "--distance-m"}},
      {"lights calibrate", {"--light-distance", "--light-distance-m"}},
      {"library", {"--sphere-size", "--sphere-size-px"}},
      {"report", {"--angles", "--angles-deg", "--render-size", "--render-size-px"}},
      {"check", {"--min-samples", "--min-pairs"}},
  };
  for (const auto& c : commands) {
    const std::string help = RunIbrdf(std::string(c.command) + " --help").output;
    for (size_t i = 0; i + 1 < c.renamed.size(); i += 2) {
      const std::string& old_name = c.renamed[i];
      const std::string& new_name = c.renamed[i + 1];
      EXPECT_NE(help.find("  " + new_name + " "), std::string::npos) << c.command << " " << new_name << "\n" << help;
      EXPECT_EQ(help.find("  " + old_name + " "), std::string::npos) << c.command << " " << old_name << "\n" << help;
      EXPECT_EQ(help.find(old_name + ","), std::string::npos) << c.command << " " << old_name << "\n" << help;
    }
  }
  // The old and the new name write the same session; the old one warns.
  ScratchDir dir;
  const std::string synth = std::string("synth --material ") + IBRDF_SAMPLES_DIR +
                            "/materials/lambertian50.json --photos 1 --width 48 --height 36 --effects none --out ";
  const RunResult by_new =
      RunIbrdf(synth + dir / "new" + " --radius-m 0.03 --camera-distance-m 0.9 --read-noise-e 2", true);
  ASSERT_EQ(by_new.exit_code, 0) << by_new.output;
  EXPECT_EQ(by_new.output.find("deprecated"), std::string::npos) << by_new.output;
  const RunResult by_old = RunIbrdf(synth + dir / "old" + " --radius 0.03 --camera-distance 0.9 --read-noise 2", true);
  ASSERT_EQ(by_old.exit_code, 0) << by_old.output;
  EXPECT_NE(by_old.output.find("warning: --radius is deprecated; use --radius-m"), std::string::npos) << by_old.output;
  EXPECT_NE(by_old.output.find("warning: --camera-distance is deprecated; use --camera-distance-m"), std::string::npos)
      << by_old.output;
  const nlohmann::json a = ReadJson(dir / "new/session.json"), b = ReadJson(dir / "old/session.json");
  EXPECT_EQ(a["sample"]["radius"], 0.03);
  EXPECT_EQ(a["sample"], b["sample"]);
  EXPECT_EQ(a["photos"], b["photos"]);
  const RunResult both = RunIbrdf(synth + dir / "both" + " --radius 0.03 --radius-m 0.03");
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_FALSE(fs::exists(dir / "both"));
}

// An option value that a stage's options Check() rejects is a usage error: exit 2, the flags and the
// failed constraint named, nothing written; bad input (a missing file) stays exit 1.
TEST(ReportCli, BadOptionValuesAreUsageErrors) {
  ScratchDir dir;
  const std::string material = std::string(IBRDF_SAMPLES_DIR) + "/materials/lambertian50.json";
  const struct {
    std::string arguments, named, output;
  } cases[] = {
      {"derender " + dir / "none" + " --out " + dir / "x.npy" + " --stride 0", "--stride >= 1", dir / "x.npy"},
      {"derender " + dir / "none" + " --out " + dir / "x.npy" + " --max-theta-i-deg 95", "--max-theta-i-deg",
       dir / "x.npy"},
      {"reconstruct " + dir / "none.npy" + " --out " + dir / "r" + " --lobes 7", "--lobes", dir / "r"},
      {"reconstruct " + dir / "none.npy" + " --out " + dir / "r" + " --fill sideways", "--fill", dir / "r"},
      {"reconstruct " + dir / "none.npy" + " --out " + dir / "r" + " --degree 5", "--degree", dir / "r"},
      {"check " + dir / "none.npy" + " --out " + dir / "c.json" + " --phi-bin-deg 7", "--phi-bin-deg", dir / "c.json"},
      {"report " + dir.str() + " --out " + dir / "rep" + " --render-size-px 8", "--render-size-px", dir / "rep"},
      {"report " + dir.str() + " --out " + dir / "rep" + " --held-out 99", "--held-out", dir / "rep"},
      {"run " + dir / "none" + " --out " + dir / "run" + " --stride 0", "--stride", dir / "run"},
      {"synth --material " + material + " --out " + dir / "s" + " --photos 0", "--photos >= 1", dir / "s"},
  };
  for (const auto& c : cases) {
    const RunResult result = RunIbrdf(c.arguments);
    EXPECT_EQ(result.exit_code, 2) << c.arguments << "\n" << result.output;
    EXPECT_NE(result.output.find(c.named), std::string::npos) << c.arguments << "\n" << result.output;
    EXPECT_EQ(result.output.find("-- "), std::string::npos) << "no stage timer: " << result.output;
    EXPECT_FALSE(fs::exists(c.output)) << c.arguments;
  }
  const RunResult missing = RunIbrdf("derender " + dir / "none" + " --out " + dir / "x.npy");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
}

class RunFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(RunIbrdf(kSynth + dir_ / "a").exit_code, 0);
    ASSERT_EQ(RunIbrdf(kSynth + dir_ / "b" + " --seed 2").exit_code, 0);
  }
  ScratchDir dir_;
};

// A run folder holding another input's run is refused (its results would mix), unless --overwrite.
TEST_F(RunFolderTest, RunRefusesAnotherInputsFolderUnlessOverwrite) {
  const std::string out = dir_ / "run";
  ASSERT_EQ(RunIbrdf("run " + dir_ / "a" + " --out " + out + " --stop-after derender").exit_code, 0);
  const RunResult refused = RunIbrdf("run " + dir_ / "b" + " --out " + out + " --stop-after derender");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find(out), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find(dir_ / "a"), std::string::npos) << refused.output;  // names the other input
  EXPECT_EQ(ReadJson(out + "/run-input.json")["input"], dir_ / "a");                // nothing changed
  // The same input resumes.
  EXPECT_EQ(RunIbrdf("run " + dir_ / "a" + " --out " + out + " --stop-after derender").exit_code, 0);
  const RunResult overwritten = RunIbrdf("run " + dir_ / "b" + " --out " + out + " --stop-after derender --overwrite");
  ASSERT_EQ(overwritten.exit_code, 0) << overwritten.output;
  EXPECT_EQ(ReadJson(out + "/run-input.json")["input"], dir_ / "b");
  EXPECT_EQ(ReadJson(out + "/summary.json")["input"], dir_ / "b");
  const nlohmann::json sidecar = ReadJson(out + "/samples.npy.json");
  EXPECT_NE(sidecar["session"].get<std::string>().find(dir_ / "b"), std::string::npos) << sidecar["session"];
}

// Stage options pass through `run`, named (--lobes, --min-signal ...) or as --STAGE-args strings, into
// the stage's command line (its stamp).
TEST_F(RunFolderTest, RunPassesStageOptionsThrough) {
  const std::string out = dir_ / "run";
  const RunResult run = RunIbrdf("run " + dir_ / "a" + " --out " + out +
                                 " --no-report --lobes 1 --min-signal 0.001 --reconstruct-args '--degree 1' "
                                 "--check-args '--match-deg 0.4'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  auto has = [](const nlohmann::json& args, const std::string& flag, const std::string& value) {
    for (size_t i = 0; i + 1 < args.size(); ++i) {
      if (args[i] == flag && args[i + 1] == value) return true;
    }
    return false;
  };
  const nlohmann::json reconstruct = ReadJson(out + "/stamps/reconstruct.json")["args"];
  EXPECT_TRUE(has(reconstruct, "--lobes", "1")) << reconstruct;
  EXPECT_TRUE(has(reconstruct, "--degree", "1")) << reconstruct;
  EXPECT_TRUE(has(ReadJson(out + "/stamps/derender.json")["args"], "--min-signal", "0.001"));
  EXPECT_TRUE(has(ReadJson(out + "/stamps/check.json")["args"], "--match-deg", "0.4"));
  EXPECT_EQ(ReadJson(out + "/consistency.json")["options"]["match_deg"], 0.4);
  // The same run with its report: only the report runs, with the held-out photos asked for.
  const RunResult report = RunIbrdf("run " + dir_ / "a" + " --out " + out +
                                    " --lobes 1 --min-signal 0.001 --reconstruct-args '--degree 1' "
                                    "--check-args '--match-deg 0.4' --held-out 2");
  ASSERT_EQ(report.exit_code, 0) << report.output;
  EXPECT_TRUE(has(ReadJson(out + "/stamps/report.json")["args"], "--held-out", "2"));
  EXPECT_EQ(ReadJson(out + "/report/report-data.json")["held_out"].size(), 2u);
  // A bad pass-through value fails in its stage, naming the flag.
  const RunResult bad = RunIbrdf("run " + dir_ / "a" + " --out " + out + " --no-report --lobes 7");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("lobes"), std::string::npos) << bad.output;
}

// `report` on a run whose reconstruction lies elsewhere, with the old option names still accepted, and a
// title from the session's name (not the generator's "synth").
TEST_F(RunFolderTest, ReportFindsTheGivenReconstructionAndAcceptsOldNames) {
  const std::string out = dir_ / "my-measurement";
  ASSERT_EQ(RunIbrdf("run " + dir_ / "a" + " --out " + out + " --no-report --no-fits").exit_code, 0);
  fs::rename(out + "/reconstruction", dir_ / "recon");
  const RunResult report = RunIbrdf("report " + out + " --reconstruction " + dir_ / "recon" +
                                    " --render-size 32 --angles 20,50 --no-explorer --held-out 2");
  ASSERT_EQ(report.exit_code, 0) << report.output;
  const nlohmann::json data = ReadJson(out + "/report/report-data.json");
  EXPECT_EQ(data["reconstruction"], dir_ / "recon/brdf.binary");
  EXPECT_EQ(data["title"], "a");  // the session's name (synth names it after its folder)
  std::ifstream index(out + "/report/index.html");
  std::stringstream page;
  page << index.rdbuf();
  EXPECT_NE(page.str().find("<title>ibrdf report: a</title>"), std::string::npos);
  EXPECT_EQ(data["incidence_plane"].size(), 2u);
  EXPECT_EQ(data["held_out"].size(), 2u);
  EXPECT_FALSE(fs::exists(out + "/report/explorer.html"));
  const RunResult missing =
      RunIbrdf("report " + out + " --out " + dir_ / "r2" + " --reconstruction " + dir_ / "nowhere");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find(dir_ / "nowhere"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(dir_ / "r2"));
  // check: the old --min-samples and the new --min-pairs are the same option.
  const RunResult check = RunIbrdf("check " + out + "/samples.npy --out " + dir_ / "c.json" + " --min-samples 7");
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_EQ(ReadJson(dir_ / "c.json")["options"]["min_samples_per_bin"], 7);
  EXPECT_TRUE(ReadJson(dir_ / "c.json").contains("bilateral_symmetry"));
}

}  // namespace
}  // namespace ibrdf

namespace ibrdf {
namespace {

// The README's demo figures come from a run's summary.json through scripts/readme_figures.py, not typed:
// the script writes the block (headline lines and the stage-time table) and its --check holds the
// README's block to the script's format (every line; the values are the run's).
int Python(const std::string& arguments) {
  const std::string script = std::string(IBRDF_SAMPLES_DIR) + "/../scripts/readme_figures.py";
  return testing::RunShell("/usr/bin/python3 " + script + " " + arguments + " 2>&1").exit_code;
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ReportCli, ReadmeFiguresAreRegeneratedFromTheRun) {
  ScratchDir dir;
  const nlohmann::json summary = {
      {"samples", {{"accepted", 1234}, {"photos", 20}}},
      {"timings_s", {{"synth", 6.0}, {"derender", 10.0}, {"reconstruct", 10.04}, {"stages_total", 26.04}}},
      {"truth",
       {{"samples_median_rel_error", {0.01, 0.02, 0.03}},
        {"brdf_rel_rmse", {0.004, 0.005, 0.006}},
        {"brdf_cells_scored", 777}}},
      {"consistency",
       {{"reciprocity", 0.0012},
        {"reciprocity_p95", 0.003},
        {"bilateral_symmetry", 0.0034},
        {"bilateral_symmetry_p95", 0.0051}}},
      {"report", "/x/report/index.html"}};
  { std::ofstream(dir / "summary.json") << summary.dump(); }
  const std::string typed =
      "intro\n<!-- readme-figures -->\n```\n1117060 samples; stages took 146.8 s\n```\n<!-- /readme-figures "
      "-->\nrest\n";
  { std::ofstream(dir / "README.md") << typed; }
  EXPECT_NE(Python("--check " + dir / "README.md"), 0) << "a typed block is not the script's";
  ASSERT_EQ(Python(dir.str() + " --update " + dir / "README.md"), 0);
  const std::string readme = Slurp(dir / "README.md");
  EXPECT_EQ(readme.find("146.8"), std::string::npos) << readme;
  EXPECT_NE(readme.find("1234 samples from 20 photos; stages took 26.0 s"), std::string::npos) << readme;
  EXPECT_NE(readme.find("Reciprocity error 0.12 %, bilateral-symmetry error 0.34 % (medians over bins; 95th "
                        "percentiles 0.30 %, 0.51 %)"),
            std::string::npos)
      << readme;
  EXPECT_NE(readme.find("over 777 MERL cells"), std::string::npos) << readme;
  EXPECT_NE(readme.find("| reconstruct | 10.0 | 39 % |"), std::string::npos) << readme;
  EXPECT_NE(readme.find("| total | 26.0 | 100 % |"), std::string::npos) << readme;
  EXPECT_EQ(readme.rfind("intro\n", 0), 0u);
  EXPECT_NE(readme.find("-->\nrest\n"), std::string::npos) << readme;
  EXPECT_EQ(Python("--check " + dir / "README.md"), 0) << readme;
  // A value edited by hand into another shape fails the check.
  std::string edited = readme;
  edited.replace(edited.find("| total | 26.0 |"), 16, "| total | 26 s |");
  { std::ofstream(dir / "README.md") << edited; }
  EXPECT_NE(Python("--check " + dir / "README.md"), 0);
  // No summary: an error naming it, the README untouched.
  EXPECT_NE(Python(dir / "nowhere" + " --update " + dir / "README.md"), 0);
  EXPECT_EQ(Slurp(dir / "README.md"), edited);
}

// The repository's README shows the block the script writes (its format; the values are a demo run's).
TEST(ReportCli, TheReadmesFiguresHaveTheScriptsFormat) {
  const std::string readme = std::string(IBRDF_SAMPLES_DIR) + "/../README.md";
  const testing::RunResult check = testing::RunShell("/usr/bin/python3 " + std::string(IBRDF_SAMPLES_DIR) +
                                                     "/../scripts/readme_figures.py --check " + readme + " 2>&1");
  EXPECT_EQ(check.exit_code, 0) << check.output;
}

}  // namespace
}  // namespace ibrdf
