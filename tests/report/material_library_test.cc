// The material library (report/material_library.h) on hand-made run folders: a finished run's figures,
// a failed run's error from its log (also after an earlier success), an incomplete run, absent
// optional files, and the folder rules (only a library is replaced; never a folder holding a run; a
// session folder is no run).
#include "report/material_library.h"

#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::ScratchDir;

void Write(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
}

const char* kSummary = R"({"format": "ibrdf-run", "version": 1, "input": "/data/hat", "session_name": "hat",
  "samples": {"accepted": 12345, "photos": 20},
  "consistency": {"reciprocity": 0.01, "isotropy": 0.02},
  "reconstruction": {"table": {"cells_measured": 900, "cells_unsupported": 100},
                     "fits": {"ggx": {"rel_rms_vs_samples": 0.07}}},
  "timings_s": {"stages_total": 12.5}})";

TEST(MaterialLibrary, RunFoldersAreNamedAfterTheirFolder) {
  testing::ScratchDir dir;
  fs::create_directories(dir / "runs/felt");
  const std::vector<LibraryEntry> entries = LibraryEntriesOfRuns({dir / "runs/felt"});
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].name, "felt");
  EXPECT_EQ(entries[0].run_dir, dir / "runs/felt");
  EXPECT_THROW(LibraryEntriesOfRuns({dir / "runs/none"}), Error);
}

// A session folder given as a run (the user forgot `ibrdf run`) is refused by name, with the remedy;
// a run folder that happens to hold a session.json beside its outputs is still a run.
TEST(MaterialLibrary, ASessionFolderIsNoRunFolder) {
  ScratchDir dir;
  Write(dir / "hat/session.json", "{}");
  const std::string message = testing::ErrorOf([&] { LibraryEntriesOfRuns({dir / "hat"}); });
  EXPECT_NE(message.find(dir / "hat"), std::string::npos) << message;
  EXPECT_NE(message.find("is a session folder"), std::string::npos) << message;
  EXPECT_NE(message.find("ibrdf run"), std::string::npos) << message;
  Write(dir / "recipe/recipe.json", "{}");
  EXPECT_NE(testing::ErrorOf([&] { LibraryEntriesOfRuns({dir / "recipe"}); }).find("is a recipe folder"),
            std::string::npos);
  Write(dir / "hat/summary.json", kSummary);
  EXPECT_EQ(LibraryEntriesOfRuns({dir / "hat"}).size(), 1u);
}

TEST(MaterialLibrary, AFinishedRunsFiguresComeFromItsSummary) {
  ScratchDir dir;
  Write(dir / "run/summary.json", kSummary);
  const nlohmann::json r = LibraryRecord({"hat", dir / "run", "", ""});
  EXPECT_EQ(r.at("status"), "ok");
  EXPECT_EQ(r.at("source"), "/data/hat");
  EXPECT_EQ(r.at("figures").at("samples"), 12345);
  EXPECT_DOUBLE_EQ(r.at("figures").at("table_coverage").get<double>(), 0.9);
  EXPECT_DOUBLE_EQ(r.at("figures").at("bilateral_symmetry").get<double>(), 0.02);
  EXPECT_DOUBLE_EQ(r.at("figures").at("fits").at("ggx").get<double>(), 0.07);
  EXPECT_TRUE(r.at("figures").at("brdf_rel_rmse").is_null()) << "a real session has no truth";
  EXPECT_DOUBLE_EQ(r.at("timings_s").at("stages_total").get<double>(), 12.5);
}

TEST(MaterialLibrary, AFailedRunIsListedWithItsErrorEvenAfterAnEarlierSuccess) {
  ScratchDir dir;
  Write(dir / "run/summary.json", kSummary);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  Write(dir / "hat.log",
        "== run 4: derender\nibrdf: error: /data/hat/photos/003.png: cannot read\n"
        "ibrdf: error: ibrdf run: stage derender failed (exit 1); fix the cause and run again to resume from it\n");
  const nlohmann::json r = LibraryRecord({"hat", dir / "run", "/data/hat", dir / "hat.log"});
  EXPECT_EQ(r.at("status"), "failed");
  EXPECT_EQ(r.at("error"), "/data/hat/photos/003.png: cannot read");
  EXPECT_EQ(r.at("errors").size(), 2u);
  EXPECT_FALSE(r.contains("figures")) << "no stale figures for a failed run";
  // Run again successfully afterwards: the newer summary wins.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  Write(dir / "run/summary.json", kSummary);
  EXPECT_EQ(LibraryRecord({"hat", dir / "run", "/data/hat", dir / "hat.log"}).at("status"), "ok");
}

TEST(MaterialLibrary, ARunWithoutSummaryOrErrorIsIncomplete) {
  ScratchDir dir;
  fs::create_directories(dir / "run");
  const nlohmann::json r = LibraryRecord({"hat", dir / "run", "", ""});
  EXPECT_EQ(r.at("status"), "incomplete");
  EXPECT_NE(r.at("error").get<std::string>().find("no summary.json"), std::string::npos);
}

TEST(MaterialLibrary, MissingOptionalFilesAreListedAsAbsentAndTheIndexIsWritten) {
  ScratchDir dir;
  Write(dir / "runs/hat/summary.json", kSummary);
  Write(dir / "runs/hat/reconstruction/ggx.json", "{}");
  Write(dir / "runs/hat/reconstruction/ggx.pbrt", "Material");
  Write(dir / "runs/bad/x", "");
  Write(dir / "bad.log", "ibrdf: error: broken\n");
  LibraryOptions options;
  options.out_dir = dir / "lib";
  const LibraryResult result =
      BuildLibrary({{"hat", dir / "runs/hat", "", ""}, {"bad", dir / "runs/bad", "", dir / "bad.log"}}, options);
  EXPECT_TRUE(result.success);
  EXPECT_EQ(result.materials, 1);
  EXPECT_EQ(result.failed, 1);
  const nlohmann::json index = nlohmann::json::parse(std::ifstream(dir / "lib/index.json"));
  EXPECT_EQ(index.at("format"), "ibrdf-library");
  const nlohmann::json& hat = index.at("materials")[0];
  EXPECT_EQ(hat.at("files").at("fits")[0], "materials/hat/hat.ggx.json");
  EXPECT_EQ(hat.at("files").at("snippets")[0], "materials/hat/hat.ggx.pbrt");
  EXPECT_TRUE(fs::exists(dir / "lib/materials/hat/hat.ggx.pbrt"));
  for (const char* absent : {"merl", "bsdf", "report", "domain"}) {
    EXPECT_NE(hat.at("absent").dump().find(absent), std::string::npos) << absent;
  }
  EXPECT_TRUE(fs::exists(dir / "lib/materials/bad/bad.log"));
  EXPECT_NE(
      std::string(std::istreambuf_iterator<char>(std::ifstream(dir / "lib/index.html").rdbuf()), {}).find("broken"),
      std::string::npos);
  // A second build replaces the library; a folder that is not one needs overwrite.
  EXPECT_TRUE(BuildLibrary({{"hat", dir / "runs/hat", "", ""}}, options).success);
  Write(dir / "other/file.txt", "mine");
  options.out_dir = dir / "other";
  EXPECT_NE(testing::ErrorOf([&] {
              BuildLibrary({{"hat", dir / "runs/hat", "", ""}}, options);
            }).find("is not an ibrdf library"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "other/file.txt"));
  // Never a library folder that holds a run: it would be replaced.
  options.out_dir = dir / "runs";
  options.overwrite = true;
  EXPECT_NE(testing::ErrorOf([&] {
              BuildLibrary({{"hat", dir / "runs/hat", "", ""}}, options);
            }).find("contain one another"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "runs/hat/summary.json"));
}

TEST(MaterialLibrary, DefaultOptionsAreValid) {
  LibraryOptions options;
  options.out_dir = "lib";
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.sphere_size = 4;
  EXPECT_FALSE(options.Check(&why));
}

}  // namespace
}  // namespace ibrdf
