// `ibrdf synth --material-map FILE` on the command line: the map replaces --material, truth.json keeps
// the map (materials embedded), a bad map is refused naming its file and field, and the tools that
// compare with one true material say that this truth has none; `run --spatial` measures each group of
// the map's recipe as a material of its own.
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/json_reader.h"
#include "core/math.h"
#include "synth/material_map.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::ScratchDir;

const char kSmall[] = " --width 160 --height 120 --photos 3 --effects none";

// A map in `dir`/maps/map.json naming two materials copied into `dir`/materials (paths relative to the
// map), with `change` applied to its JSON.
std::string WriteMap(const ScratchDir& dir, const std::function<void(nlohmann::json*)>& change = {}) {
  fs::create_directories(dir / "maps");
  fs::create_directories(dir / "materials");
  fs::copy_file(testing::MaterialPath("bluepaint"), dir / "materials/bluepaint.json",
                fs::copy_options::overwrite_existing);
  fs::copy_file(testing::MaterialPath("felt"), dir / "materials/felt.json", fs::copy_options::overwrite_existing);
  nlohmann::json map = {{"kind", "stripes"},
                        {"centre", {0.0, 0.0, 0.0}},
                        {"axis", {0.0, 0.0, 1.0}},
                        {"materials", {"../materials/bluepaint.json", "../materials/felt.json"}},
                        {"stripes", {0, 1, 0, 1, 0, 1}},
                        {"blend_mm", {0, 15, 0, 15, 0, 0}}};
  if (change) change(&map);
  std::ofstream(dir / "maps/map.json") << map.dump(2);
  return dir / "maps/map.json";
}

TEST(SynthMaterialMapCli, TruthHoldsTheMapAndRoundTrips) {
  ScratchDir dir;
  const std::string map_path = WriteMap(dir);
  const auto run = RunIbrdf("synth --material-map " + map_path + " --out " + (dir / "s") + kSmall, /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("material map"), std::string::npos) << run.output;
  const nlohmann::json truth = ReadJsonFile(dir / "s/truth.json");
  EXPECT_FALSE(truth.contains("material"));
  EXPECT_EQ(truth.at("material_map_name"), map_path);
  // The embedded map is the file's map: the same names, weights and values everywhere.
  const MaterialMap back = MaterialMap::FromJson(truth.at("material_map"), dir / "s/truth.json");
  const MaterialMap file = MaterialMap::Load(map_path);
  ASSERT_EQ(back.NumMaterials(), 2u);
  EXPECT_EQ(back.Name(0), "bluepaint");
  EXPECT_EQ(back.Name(1), "felt");
  const Eigen::Vector3d wi(0.3, 0.1, 0.95), wo(-0.2, 0.4, 0.89);
  for (double deg = 0.5; deg < 360.0; deg += 2.9) {
    const Eigen::Vector3d p(0.04 * std::cos(deg * kDegree), 0.04 * std::sin(deg * kDegree), -0.01);
    EXPECT_NEAR((back.Weights(p) - file.Weights(p)).norm(), 0.0, 1e-12) << deg;
    EXPECT_NEAR((back.Eval(p, wi, wo) - file.Eval(p, wi, wo)).norm(), 0.0, 1e-9 * file.Eval(p, wi, wo).norm()) << deg;
    EXPECT_EQ(back.Label(p), file.Label(p));
    EXPECT_NEAR(back.BoundaryDistance(p), file.BoundaryDistance(p), 1e-12);
  }
  // A single-material comparison says why it cannot be made, naming the field.
  ASSERT_EQ(RunIbrdf("derender " + (dir / "s") + " --stride 4 --out " + (dir / "s.npy")).exit_code, 0);
  const auto compare = RunIbrdf("compare " + (dir / "s.npy") + " --out " + (dir / "c.json"));
  EXPECT_NE(compare.exit_code, 0);
  EXPECT_NE(compare.output.find("truth is spatially varying: no single-material comparison"), std::string::npos)
      << compare.output;
  EXPECT_NE(compare.output.find("/material_map"), std::string::npos) << compare.output;
  EXPECT_FALSE(fs::exists(dir / "c.json"));
}

TEST(SynthMaterialMapCli, BadMapFilesAreRefusedNamingTheFileAndField) {
  ScratchDir dir;
  struct Case {
    std::function<void(nlohmann::json*)> change;
    std::string field;  // a word the message must hold
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json* m) { m->erase("stripes"); }, "\"stripes\""},
      {[](nlohmann::json* m) { (*m)["stripes"] = {0, 1, 2, 0, 1, 0}; }, "stripe material 2"},
      {[](nlohmann::json* m) {
         (*m)["blend_mm"] = {0, 1};
       },
       "\"blend_mm\""},
      {[](nlohmann::json* m) {
         (*m)["axis"] = {0, 0};
       },
       "\"axis\""},
      {[](nlohmann::json* m) { (*m)["kind"] = "rings"; }, "rings"},
      {[](nlohmann::json* m) {
         (*m)["materials"] = {"../materials/felt.json", "../materials/none.json"};
       },
       "/materials/1"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string map_path = WriteMap(dir, cases[i].change);
    const std::string out = dir / ("s" + std::to_string(i));
    const auto run = RunIbrdf("synth --material-map " + map_path + " --out " + out + kSmall);
    EXPECT_NE(run.exit_code, 0) << i;
    EXPECT_NE(run.output.find("map.json"), std::string::npos) << i << ": " << run.output;
    EXPECT_NE(run.output.find(cases[i].field), std::string::npos) << i << ": " << run.output;
    EXPECT_FALSE(fs::exists(out)) << i;
  }
  // Not JSON at all.
  std::ofstream(dir / "maps/map.json") << "{\"kind\": ";
  const auto broken = RunIbrdf("synth --material-map " + (dir / "maps/map.json") + " --out " + (dir / "b") + kSmall);
  EXPECT_NE(broken.exit_code, 0);
  EXPECT_NE(broken.output.find("map.json"), std::string::npos) << broken.output;
}

TEST(SynthMaterialMapCli, ExactlyOneOfMaterialAndMapIsGiven) {
  ScratchDir dir;
  const std::string map_path = WriteMap(dir);
  const auto both = RunIbrdf("synth --material " + testing::MaterialPath("felt") + " --material-map " + map_path +
                             " --out " + (dir / "b") + kSmall);
  EXPECT_EQ(both.exit_code, 2) << both.output;
  EXPECT_NE(both.output.find("--material excludes --material-map"), std::string::npos) << both.output;
  const auto neither = RunIbrdf("synth --out " + (dir / "n") + kSmall);
  EXPECT_EQ(neither.exit_code, 2) << neither.output;
  EXPECT_NE(neither.output.find("--material or --material-map is required"), std::string::npos) << neither.output;
  EXPECT_FALSE(fs::exists(dir / "b"));
  EXPECT_FALSE(fs::exists(dir / "n"));
}

// A recipe naming a material map (relative to the recipe) runs until the uniformity check, which stops
// it: the one BRDF averages two materials, and the map says where. Accepted by name, the run goes on;
// the single-material comparison is not applicable, and the summary says why and records the accepted
// verdict.
TEST(SynthMaterialMapCli, RecipeWithAMapStopsAtUniformityAndRunsWhenAccepted) {
  ScratchDir dir;
  WriteMap(dir);
  std::ofstream(dir / "maps/recipe.json")
      << nlohmann::json{{"format", "ibrdf-recipe"},
                        {"version", 1},
                        {"name", "striped"},
                        {"material_map", "map.json"},
                        {"synth", {"--width", "160", "--height", "120", "--photos", "4", "--effects", "none"}}}
             .dump();
  const std::string run_line = "run " + (dir / "maps") + " --out " + (dir / "r") + " --no-report --no-fits --stride 2";
  const auto stopped = RunIbrdf(run_line, /*quiet=*/true);
  EXPECT_EQ(stopped.exit_code, 1) << stopped.output;
  EXPECT_NE(stopped.output.find("uniformity.cells: fail"), std::string::npos) << stopped.output;
  EXPECT_NE(stopped.output.find("stage uniformity failed"), std::string::npos) << stopped.output;
  const nlohmann::json measured = ReadJsonFile(dir / "r/uniformity/uniformity.json");
  EXPECT_GT(measured.at("deviating_fraction").get<double>(), 0.15);
  EXPECT_TRUE(fs::exists(dir / "r/uniformity/map.png"));

  const auto run = RunIbrdf(run_line + " --uniformity-args \"--accept uniformity.cells\"", /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("accepted by the user: uniformity.cells"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("truth is spatially varying: no single-material comparison"), std::string::npos)
      << run.output;
  const nlohmann::json summary = ReadJsonFile(dir / "r/summary.json");
  // The second run resumes: synth to reconstruct are complete, uniformity runs again, with the accept.
  EXPECT_EQ(summary.at("stages").at("synth").at("status"), "skipped");
  EXPECT_EQ(summary.at("stages").at("uniformity").at("status"), "ran");
  EXPECT_EQ(summary.at("stages").at("compare").at("status"), "not_applicable");
  EXPECT_EQ(summary.at("stages").at("compare").at("reason"),
            "truth is spatially varying: no single-material comparison");
  EXPECT_EQ(summary.at("truth").at("spatially_varying"), true);
  EXPECT_FALSE(summary.at("truth").contains("samples_median_rel_error"));
  EXPECT_FALSE(summary.at("truth").contains("brdf_rel_rmse"));
  EXPECT_FALSE(fs::exists(dir / "r/truth-comparison.json"));
  EXPECT_TRUE(ReadJsonFile(dir / "r/synth/truth.json").contains("material_map"));
  bool recorded = false;
  for (const nlohmann::json& verdict : summary.at("verdicts")) {
    if (verdict.value("check", "") == "uniformity.cells") recorded = verdict.value("accepted", false);
  }
  EXPECT_TRUE(recorded) << summary.at("verdicts").dump(2);
  EXPECT_EQ(summary.at("stages").at("materials").at("status"), "not_applicable");

  // --spatial: the groups measured as materials, scored against the map. At 160 x 120 and stride 2
  // the felt's group holds under the default 1000 samples a group needs: a material found and not
  // measured stops the run, its evidence written.
  const auto too_small = RunIbrdf(run_line + " --spatial", /*quiet=*/true);
  EXPECT_EQ(too_small.exit_code, 1) << too_small.output;
  EXPECT_NE(too_small.output.find("materials.measured: fail"), std::string::npos) << too_small.output;
  EXPECT_NE(too_small.output.find("--accept materials.measured"), std::string::npos) << too_small.output;
  EXPECT_EQ(ReadJsonFile(dir / "r/materials/materials.json").at("verdicts").at(0).at("verdict"), "fail");
  // With 500 samples enough for a group, both are measured.
  const auto spatial = RunIbrdf(run_line + " --spatial --materials-args \"--min-group-samples 500\"", /*quiet=*/true);
  ASSERT_EQ(spatial.exit_code, 0) << spatial.output;
  const nlohmann::json with = ReadJsonFile(dir / "r/summary.json");
  EXPECT_EQ(with.at("stages").at("materials").at("status"), "ran");
  const nlohmann::json materials = ReadJsonFile(dir / "r/materials/materials.json");
  ASSERT_EQ(materials.at("groups").size(), 2u) << materials.dump(2);
  EXPECT_EQ(materials.at("truth"), "map");
  // Labels on this small capture (the squash's 98 % bound is for 800 x 600, docs/spatial.md).
  EXPECT_GE(materials.at("labels").at("right_fraction").get<double>(), 0.85) << materials.dump(2);
  std::set<std::string> names;
  for (const nlohmann::json& group : materials.at("groups")) {
    ASSERT_TRUE(group.at("reconstructed").get<bool>()) << group.dump(2);
    EXPECT_TRUE(fs::exists(dir / ("r/materials/" + group.at("folder").get<std::string>() + "/brdf.binary")));
    names.insert(group.at("truth_name").get<std::string>());
  }
  EXPECT_EQ(names.size(), 2u) << materials.dump(2);
  EXPECT_EQ(with.at("materials").at("groups").size(), 2u);
  // Every cell as a combination of the two, judged and scored against the map.
  EXPECT_EQ(with.at("materials").at("weights").at("bases").size(), 2u) << with.at("materials").dump(2);
  EXPECT_GT(with.at("materials").at("weights").at("cells_fitted").get<int>(), 0);
  EXPECT_TRUE(with.at("materials").at("weights").contains("truth"));
  std::set<std::string> checks;
  for (const nlohmann::json& verdict : with.at("verdicts")) {
    if (verdict.value("stage", "") == "materials") checks.insert(verdict.value("check", ""));
  }
  EXPECT_EQ(checks, (std::set<std::string>{"materials.measured", "materials.cells"})) << with.at("verdicts").dump(2);
  // The photo with the most samples predicted from the model, far closer than the one average BRDF.
  const nlohmann::json& prediction = with.at("materials").at("prediction");
  EXPECT_FALSE(prediction.at("held_out").get<bool>());
  ASSERT_TRUE(prediction.at("image").is_string()) << prediction.dump(2);
  EXPECT_TRUE(fs::exists(dir / ("r/materials/" + prediction.at("image").get<std::string>())));
  EXPECT_LT(2.0 * prediction.at("model_median_abs_rel_error").get<double>(),
            prediction.at("single_brdf_median_abs_rel_error").get<double>())
      << prediction.dump(2);

  // A held-out photo: its samples are in no group (too few photos are left here to fit cells).
  const auto held = RunIbrdf("materials " + (dir / "r/samples.npy") + " --uniformity " +
                                 (dir / "r/uniformity/uniformity.json") + " --photo 1 --hold-out --no-fits --no-bsdf" +
                                 " --min-group-samples 100 --accept all --out " + (dir / "held"),
                             /*quiet=*/true);
  ASSERT_EQ(held.exit_code, 0) << held.output;
  const nlohmann::json held_json = ReadJsonFile(dir / "held/materials.json");
  const nlohmann::json& counts = held_json.at("samples");
  EXPECT_GT(counts.at("held_out").get<uint64_t>(), 0u) << counts.dump();
  uint64_t in_groups = 0;
  for (const nlohmann::json& group : held_json.at("groups")) in_groups += group.at("samples").get<uint64_t>();
  EXPECT_EQ(in_groups + counts.at("mixed").get<uint64_t>() + counts.at("ungrouped").get<uint64_t>() +
                counts.at("not_located").get<uint64_t>() + counts.at("held_out").get<uint64_t>(),
            counts.at("rows").get<uint64_t>())
      << counts.dump();
  EXPECT_TRUE(held_json.at("prediction").at("held_out").get<bool>());
  EXPECT_EQ(held_json.at("prediction").at("photo"), 1);
  EXPECT_NE(RunIbrdf("materials " + (dir / "r/samples.npy") + " --uniformity " + (dir / "r/uniformity/uniformity.json") +
                         " --hold-out --out " + (dir / "held2"),
                     /*quiet=*/true)
                .output.find("a held-out photo must be named (--photo N)"),
            std::string::npos);
  EXPECT_NE(RunIbrdf("materials " + (dir / "r/samples.npy") + " --uniformity " + (dir / "r/uniformity/uniformity.json") +
                         " --photo 99 --out " + (dir / "held3"),
                     /*quiet=*/true)
                .output.find("photo 99 to predict: the session has 4 photos (0 to 3)"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "held3"));
  EXPECT_NE(spatial.output.find("labels right on"), std::string::npos) << spatial.output;
}

}  // namespace
}  // namespace ibrdf
