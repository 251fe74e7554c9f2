// The uniformity cells grouped into materials: clusters of known ratios are found with their cells, a
// uniform scatter and materials closer than the separation give one, a cluster of too few cells is not
// counted, a mix of two is their blend; on a synthetic sphere of three materials in six sharp stripes the cells' labels match the
// map's away from the boundaries.
#include "spatial/material_clusters.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "core/sample_file.h"
#include "derender/derenderer.h"
#include "spatial/uniformity.h"
#include "synth/material_map.h"
#include "synth/synthetic.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

// `n` cells scattered by `noise` (relative, per channel) about each of `centres`.
std::vector<Eigen::Vector3d> Scatter(const std::vector<Eigen::Vector3d>& centres, const std::vector<int>& n,
                                     double noise, std::vector<int>* truth) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<Eigen::Vector3d> cells;
  for (size_t c = 0; c < centres.size(); ++c) {
    for (int i = 0; i < n[c]; ++i) {
      Eigen::Vector3d r;
      for (int k = 0; k < 3; ++k) r[k] = centres[c][k] * std::exp(gauss(rng));
      cells.push_back(r);
      truth->push_back(int(c));
    }
  }
  return cells;
}

TEST(MaterialClusters, ThreeMaterialsAreFoundWithTheirCells) {
  std::vector<int> truth;
  std::vector<Eigen::Vector3d> cells = Scatter(
      {{1.0, 1.0, 1.0}, {2.0, 1.0, 0.5}, {0.5, 0.8, 1.5}}, {400, 300, 200}, 0.03, &truth);
  cells.push_back(Eigen::Vector3d(std::nan(""), 1.0, 1.0));  // not scored in red: not clustered
  const MaterialClusters clusters = ClusterMaterials(cells, MaterialClusterOptions());
  ASSERT_EQ(clusters.count, 3) << clusters.BriefReport();
  EXPECT_EQ(clusters.clustered, 900u);
  EXPECT_EQ(clusters.cell_label.back(), -1);
  // Each true group maps to one cluster, all its cells with it.
  for (int group = 0; group < 3; ++group) {
    const auto first = std::find(truth.begin(), truth.end(), group) - truth.begin();
    const int label = clusters.cell_label[first];
    for (size_t i = 0; i < truth.size(); ++i) {
      if (truth[i] == group) {
        EXPECT_EQ(clusters.cell_label[i], label) << i;
      }
    }
    EXPECT_NEAR(clusters.share[label], group == 0 ? 4.0 / 9 : group == 1 ? 3.0 / 9 : 2.0 / 9, 1e-12);
  }
  EXPECT_NE(clusters.BriefReport().find("form 3 groups"), std::string::npos) << clusters.BriefReport();
}

// Three materials and the cells of a smooth boundary between two of them (their values halfway): four
// groups, of which the halfway one is named their blend, and three materials.
TEST(MaterialClusters, ABoundarysMixIsABlendNotAMaterial) {
  std::vector<int> truth;
  const Eigen::Vector3d a(3.0, 1.0, 0.3), b(0.3, 1.0, 3.0), dark(0.2, 0.2, 0.2);
  const std::vector<Eigen::Vector3d> cells =
      Scatter({a, b, dark, 0.5 * (a + b)}, {300, 300, 300, 100}, 0.03, &truth);
  const MaterialClusters clusters = ClusterMaterials(cells, MaterialClusterOptions());
  ASSERT_EQ(clusters.count, 4) << clusters.BriefReport();
  EXPECT_EQ(clusters.materials, 3) << clusters.BriefReport();
  const int mix = clusters.cell_label.back(), of_a = clusters.cell_label.front(), of_b = clusters.cell_label[300];
  EXPECT_TRUE(clusters.IsBlend(mix));
  EXPECT_FALSE(clusters.IsBlend(of_a));
  EXPECT_FALSE(clusters.IsBlend(clusters.cell_label[600]));
  EXPECT_EQ(std::min(clusters.blend_of[mix][0], clusters.blend_of[mix][1]), std::min(of_a, of_b));
  EXPECT_EQ(std::max(clusters.blend_of[mix][0], clusters.blend_of[mix][1]), std::max(of_a, of_b));
  EXPECT_NE(clusters.BriefReport().find("3 materials, group " + std::to_string(mix) + " a blend"), std::string::npos)
      << clusters.BriefReport();
  // Two materials and their mix: the mix is their blend too (two materials remain).
  truth.clear();
  const MaterialClusters two = ClusterMaterials(Scatter({a, b, 0.5 * (a + b)}, {300, 300, 300}, 0.03, &truth), {});
  ASSERT_EQ(two.count, 3) << two.BriefReport();
  EXPECT_EQ(two.materials, 2) << two.BriefReport();
}

TEST(MaterialClusters, OneMaterialCloseMaterialsAndATinyPatchGiveOne) {
  std::vector<int> truth;
  EXPECT_EQ(ClusterMaterials(Scatter({{1.0, 1.0, 1.0}}, {1000}, 0.05, &truth), {}).count, 1);
  truth.clear();
  // 1.15x apart in red only: under the 1.6x separation.
  EXPECT_EQ(ClusterMaterials(Scatter({{1.0, 1.0, 1.0}, {1.15, 1.0, 1.0}}, {500, 500}, 0.01, &truth), {}).count, 1);
  truth.clear();
  // 2x apart but 2 % of the cells: under the 5 % share.
  EXPECT_EQ(ClusterMaterials(Scatter({{1.0, 1.0, 1.0}, {2.0, 2.0, 2.0}}, {980, 20}, 0.01, &truth), {}).count, 1);
  EXPECT_EQ(ClusterMaterials({}, {}).count, 0);
  MaterialClusterOptions bad;
  bad.max_materials = 0;
  std::string why;
  EXPECT_FALSE(bad.Check(&why));
}

// Six sharp stripes about the vertical axis, red, blue and grey Lambertian twice over, on a sphere of
// 320 x 240 photos: the check finds three materials, and the cells further than 2 mm plus half a cell's
// diagonal from a boundary carry the map's label (under the best matching of clusters to materials) in
// at least 98 % of cases.
TEST(MaterialClusters, StripesOfThreeMaterialsAreLabelledAsTheMapSays) {
  ScratchDir dir;
  SynthOptions options;
  options.rig.width = 320;
  options.rig.height = 240;
  options.rig.num_photos = 6;
  const std::vector<std::shared_ptr<const BrdfModel>> materials = {
      std::make_shared<LambertianBrdf>(Eigen::Vector3d(0.6, 0.25, 0.1)),
      std::make_shared<LambertianBrdf>(Eigen::Vector3d(0.1, 0.25, 0.6)),
      std::make_shared<LambertianBrdf>(Eigen::Vector3d(0.3, 0.3, 0.3))};
  const MaterialMap map({"red", "blue", "grey"}, materials, options.scene.origin, Eigen::Vector3d::UnitZ(),
                        {0, 1, 2, 0, 1, 2}, std::vector<double>(6, 0.0), "test map");
  WriteSyntheticSession(options, map, "test map", dir / "session", /*overwrite=*/true);
  const Session session = Session::Load(dir / "session/session.json");
  WriteSamples(dir / "samples.npy", DerenderAnalytic(session, DerenderOptions()).samples);
  const LambertianBrdf average(Eigen::Vector3d(0.33, 0.27, 0.33));
  UniformityOptions uniformity;
  uniformity.cell_m = session.sample.radius / 8.0;
  const UniformityResult result = MeasureUniformity(session, dir / "samples.npy", average, uniformity);
  ASSERT_EQ(result.materials.count, 3) << result.materials.BriefReport();
  // confusion[cluster][material] over the cells away from boundaries.
  std::array<std::array<int, 3>, 3> confusion{};
  const double margin = 0.002 + 0.5 * std::sqrt(3.0) * result.cell_m;
  for (size_t c = 0; c < result.cells.size(); ++c) {
    const int label = result.materials.cell_label[c];
    if (label < 0 || map.BoundaryDistance(result.cells[c].centre) < margin) continue;
    ++confusion[label][map.Label(result.cells[c].centre)];
  }
  std::array<int, 3> to_material = {0, 1, 2};
  int best = -1, total = 0;
  for (const auto& row : confusion) {
    for (int n : row) total += n;
  }
  std::array<int, 3> perm = {0, 1, 2};
  do {
    const int right = confusion[0][perm[0]] + confusion[1][perm[1]] + confusion[2][perm[2]];
    if (right > best) {
      best = right;
      to_material = perm;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  ASSERT_GT(total, 50);
  EXPECT_GE(double(best) / double(total), 0.98) << best << " of " << total;
  std::printf("cells away from boundaries labelled as the map: %d of %d (%.1f %%); clusters -> materials %d %d %d\n",
              best, total, 100.0 * best / total, to_material[0], to_material[1], to_material[2]);
}

}  // namespace
}  // namespace ibrdf
