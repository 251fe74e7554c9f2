// The uniformity check's groups measured as materials: on a synthetic sphere of two materials in four
// sharp stripes the samples are split by their nearest off-peak samples' groups (those on a boundary
// by neither), each group matches one material of the map on the samples away from its boundaries and
// is reconstructed close to it, and every cell is the right combination of the two; a material too
// small to reconstruct fails both verdicts; a uniform sphere gives
// one group and no second reconstruction; a uniformity.json without its grid is refused by name.
#include "spatial/material_groups.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sample_file.h"
#include "derender/derenderer.h"
#include "spatial/uniformity.h"
#include "synth/material_map.h"
#include "synth/synthetic.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

SynthOptions Small() {
  SynthOptions options;
  options.rig.width = 320;
  options.rig.height = 240;
  options.rig.num_photos = 6;
  return options;
}

MaterialGroupsOptions Quick() {
  MaterialGroupsOptions options;
  options.reconstruct.fits = false;
  options.reconstruct.bsdf = false;
  return options;
}

const std::vector<std::shared_ptr<const BrdfModel>> kMaterials = {
    std::make_shared<LambertianBrdf>(Eigen::Vector3d(0.6, 0.25, 0.1)),
    std::make_shared<LambertianBrdf>(Eigen::Vector3d(0.1, 0.25, 0.6))};

TEST(MaterialGroups, TwoMaterialsAreSplitLabelledAndReconstructedEach) {
  ScratchDir dir;
  const SynthOptions synth = Small();
  const MaterialMap map({"red", "blue"}, kMaterials, synth.scene.origin, Eigen::Vector3d::UnitZ(), {0, 1, 0, 1},
                        std::vector<double>(4, 0.0), "test map");
  WriteSyntheticSession(synth, map, "test map", dir / "session", /*overwrite=*/true);
  const Session session = Session::Load(dir / "session/session.json");
  const std::vector<BrdfSample> samples = DerenderAnalytic(session, DerenderOptions()).samples;
  WriteSamples(dir / "samples.npy", samples);
  UniformityOptions uniformity;
  uniformity.cell_m = session.sample.radius / 8.0;
  const LambertianBrdf average(Eigen::Vector3d(0.35, 0.25, 0.35));
  const UniformityResult cells = MeasureUniformity(session, dir / "samples.npy", average, uniformity);
  ASSERT_EQ(cells.materials.count, 2) << cells.materials.BriefReport();

  std::filesystem::create_directories(dir / "out");
  const MaterialGroupsResult result = MeasureMaterialGroups(session, dir / "samples.npy", cells.ToJson(true),
                                                            "uniformity.json", &map, "", Quick(), dir / "out");
  ASSERT_EQ(result.groups.size(), 2u) << result.BriefReport();
  EXPECT_EQ(result.samples, samples.size());
  EXPECT_EQ(result.not_located, 0u);
  // Every located sample in a cell the check grouped, but for cells not scored in all channels.
  EXPECT_LT(double(result.ungrouped), 0.05 * double(result.samples)) << result.BriefReport();
  EXPECT_EQ(result.groups[0].samples + result.groups[1].samples + result.ungrouped + result.mixed, result.samples);
  // The samples on a sharp boundary (their neighbours of both groups) go into neither basis: a few
  // percent, and hardly any of them away from the boundaries.
  EXPECT_GT(result.mixed, 0u);
  EXPECT_LT(double(result.mixed), 0.1 * double(result.samples)) << result.BriefReport();
  EXPECT_LT(double(result.mixed_scored), 0.01 * double(result.scored)) << result.BriefReport();
  EXPECT_GT(result.off_peak_samples, samples.size() / 2);
  EXPECT_GT(result.scored, samples.size() / 2);
  EXPECT_GE(result.labels_right, 0.98) << result.BriefReport();
  EXPECT_NE(result.groups[0].truth_material, result.groups[1].truth_material);
  for (const MaterialGroup& group : result.groups) {
    ASSERT_TRUE(group.reconstructed);
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir / "out") / group.folder / "brdf.binary"))
        << group.folder;
    ASSERT_TRUE(group.reconstruction.scored);
    // The one-material average is off by about 2x in red or blue; each group's own table is close.
    EXPECT_LT(group.reconstruction.error_against_truth.rel_rms_all, 0.05)
        << group.truth_name << ": " << group.reconstruction.error_against_truth.Brief();
  }
  const nlohmann::json json = result.ToJson();
  EXPECT_EQ(json["labels"]["confusion_groups_by_materials"].size(), 2u);
  EXPECT_NE(result.BriefReport().find("labels right on"), std::string::npos) << result.BriefReport();
  std::printf("%s\n", result.BriefReport().c_str());

  // Every cell as a combination of the two groups, its weights those of the truth (its mean over each
  // cell's samples).
  EXPECT_EQ(result.bases, (std::vector<int>{0, 1}));
  EXPECT_GT(result.weights.cells_fitted, 20u) << result.weights.BriefReport(Quick().weights);
  EXPECT_LE(result.weights.not_fitting_fraction, 0.05) << result.weights.BriefReport(Quick().weights);
  EXPECT_EQ(result.weights_scored_cells, result.weights.cells_fitted);
  // (The stripes' boundaries lie on the cells' grid planes here, so no cell straddles one.)
  EXPECT_LT(result.weights_error_median, 0.02) << result.BriefReport();
  EXPECT_LT(result.weights_error_p95, 0.05) << result.BriefReport();
  ASSERT_EQ(result.verdicts.size(), 2u);
  EXPECT_EQ(result.verdicts[0].check, "materials.measured");
  EXPECT_EQ(result.verdicts[0].level, VerdictLevel::kOk) << result.verdicts[0].Line();
  EXPECT_EQ(result.verdicts[1].check, "materials.cells");
  EXPECT_EQ(result.verdicts[1].level, VerdictLevel::kOk) << result.verdicts[1].Line();
  EXPECT_EQ(json["weights"]["cell_list"].size(), result.weights.cells.size());
  EXPECT_EQ(json["verdicts"].size(), 2u);
  // The photo with the most samples predicted from the model, at the truth's noise (without fits only
  // where both groups' tables have data: under half its samples). This uniformity.json names no
  // reconstructed BRDF (`ibrdf uniformity` records it), so there is no one-BRDF figure. An analytic
  // sphere has no mesh: neither a PLY nor a pbrt-v4 scene.
  ASSERT_TRUE(result.prediction.done);
  EXPECT_GT(result.prediction.predicted, result.prediction.samples / 3);
  EXPECT_LT(result.prediction.model_error_all, 0.02) << result.prediction.BriefReport();
  EXPECT_LT(result.prediction.model_error_all, 1.5 * result.prediction.truth_error_all + 0.002)
      << result.prediction.BriefReport();
  EXPECT_TRUE(std::isnan(result.prediction.single_error_all));
  EXPECT_FALSE(result.mesh.written);
  EXPECT_FALSE(result.pbrt.written);
  EXPECT_FALSE(json["pbrt"]["written"].get<bool>());
  EXPECT_NE(json["pbrt"]["reason"].get<std::string>().find("analytic"), std::string::npos) << json["pbrt"].dump();

  // A group too small to reconstruct: a material found and not measured fails, and its cells, expressed
  // by the other group alone, fit no combination.
  MaterialGroupsOptions strict = Quick();
  strict.min_group_samples = std::max(result.groups[0].samples, result.groups[1].samples);
  std::filesystem::create_directories(dir / "strict");
  const MaterialGroupsResult missed = MeasureMaterialGroups(session, dir / "samples.npy", cells.ToJson(true),
                                                            "uniformity.json", &map, "", strict, dir / "strict");
  ASSERT_EQ(missed.bases.size(), 1u);
  ASSERT_EQ(missed.verdicts.size(), 2u);
  EXPECT_EQ(missed.verdicts[0].level, VerdictLevel::kFail) << missed.verdicts[0].Line();
  EXPECT_NE(missed.verdicts[0].measured.find("too small"), std::string::npos) << missed.verdicts[0].Line();
  EXPECT_EQ(missed.verdicts[1].level, VerdictLevel::kFail) << missed.verdicts[1].Line();
  EXPECT_GT(missed.weights.not_fitting_fraction, 0.3) << missed.weights.BriefReport(strict.weights);
}

TEST(MaterialGroups, OneMaterialIsOneGroupNotReconstructedAgain) {
  ScratchDir dir;
  const LambertianBrdf grey(Eigen::Vector3d(0.5, 0.4, 0.3));
  const Session session = Session::Load(testing::MakeSession(dir / "session", Small(), grey));
  WriteSamples(dir / "samples.npy", DerenderAnalytic(session, DerenderOptions()).samples);
  UniformityOptions uniformity;
  uniformity.cell_m = session.sample.radius / 8.0;
  const UniformityResult cells = MeasureUniformity(session, dir / "samples.npy", grey, uniformity);
  ASSERT_EQ(cells.materials.count, 1);
  std::filesystem::create_directories(dir / "out");
  const MaterialGroupsResult result = MeasureMaterialGroups(session, dir / "samples.npy", cells.ToJson(true),
                                                            "uniformity.json", nullptr, "", Quick(), dir / "out");
  ASSERT_EQ(result.groups.size(), 1u);
  EXPECT_FALSE(result.groups[0].reconstructed);
  EXPECT_GT(result.groups[0].samples, result.samples / 2);
  EXPECT_TRUE(std::filesystem::is_empty(dir / "out"));
  EXPECT_NE(result.BriefReport().find("one material"), std::string::npos) << result.BriefReport();
  EXPECT_TRUE(result.bases.empty());
  EXPECT_TRUE(result.verdicts.empty());

  nlohmann::json old = cells.ToJson(true);
  old.erase("grid_origin");
  try {
    MeasureMaterialGroups(session, dir / "samples.npy", old, "old/uniformity.json", nullptr, "", Quick(), dir / "out");
    FAIL() << "a uniformity.json without its grid was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("old/uniformity.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("grid_origin"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
