#include "spatial/material_weights.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"

namespace ibrdf {
namespace {

Eigen::Vector3d FromSpherical(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// A glossy blue and a matte red-brown: the two bases every cell below is made of.
const GgxBrdf kGlossy(Eigen::Vector3d(0.05, 0.1, 0.4), Eigen::Vector3d(0.04, 0.04, 0.04), 0.15);
const LambertianBrdf kMatte(Eigen::Vector3d(0.5, 0.25, 0.15));

// `count` samples of cell `key` at random directions, each worth f(wi, wo) (every channel measured).
template <class F>
void AddCell(uint64_t key, int count, uint32_t seed, F f, std::vector<LocatedSample>* out) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> theta(0.0, 1.2), phi(-M_PI, M_PI);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d wi = FromSpherical(theta(rng), phi(rng)), wo = FromSpherical(theta(rng), phi(rng));
    const Eigen::Vector3d value = f(wi, wo);
    LocatedSample s;
    for (int k = 0; k < 3; ++k) {
      s.sample.wi[k] = float(wi[k]);
      s.sample.wo[k] = float(wo[k]);
      s.sample.brdf[k] = float(value[k]);
    }
    s.point = Eigen::Vector3f(float(key) * 0.003f, 0.0f, 0.0f);
    s.key = key;
    out->push_back(s);
  }
}

const CellWeights& CellOf(const MaterialWeightsResult& result, uint64_t key) {
  for (const CellWeights& cell : result.cells) {
    if (cell.key == key) return cell;
  }
  throw Error("no cell " + std::to_string(key));
}

TEST(MaterialWeights, MixedCellsGiveTheirWeightsBack) {
  std::vector<LocatedSample> samples;
  const double mixes[] = {0.0, 0.25, 0.5, 1.0};
  for (int c = 0; c < 4; ++c) {
    const double w = mixes[c];
    AddCell(uint64_t(10 - c), 200, uint32_t(c), [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
      return Eigen::Vector3d(w * kGlossy.Eval(wi, wo) + (1.0 - w) * kMatte.Eval(wi, wo));
    }, &samples);
  }
  const MaterialWeightsResult result = ProjectOntoBases(&samples, {&kGlossy, &kMatte}, MaterialWeightsOptions{});
  ASSERT_EQ(result.cells.size(), 4u);
  EXPECT_EQ(result.cells_fitted, 4u);
  EXPECT_EQ(result.cells_not_fitting, 0u);
  EXPECT_LT(result.cells[0].key, result.cells[1].key);  // by key
  for (int c = 0; c < 4; ++c) {
    const CellWeights& cell = CellOf(result, uint64_t(10 - c));
    ASSERT_TRUE(cell.fitted);
    EXPECT_TRUE(cell.fits);
    EXPECT_NEAR(cell.weights[0], mixes[c], 1e-5);
    EXPECT_NEAR(cell.weights[1], 1.0 - mixes[c], 1e-5);
    EXPECT_LT(cell.rel_rms, 1e-5);
    EXPECT_EQ(cell.dominant, mixes[c] > 0.5 ? 0 : 1);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(cell.ratio[k], 1.0, 1e-5);
  }
}

TEST(MaterialWeights, WeightsStayNonNegative) {
  // 1.2 matte minus 0.1 glossy: the unconstrained least squares wants a negative glossy weight; bounded
  // at 0, the matte weight is the one-basis least squares of the rows (each over the bases' mean).
  std::vector<LocatedSample> samples;
  const auto f = [](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
    return Eigen::Vector3d((1.2 * kMatte.Eval(wi, wo) - 0.1 * kGlossy.Eval(wi, wo)).cwiseMax(1e-4));
  };
  AddCell(1, 300, 7, f, &samples);
  const MaterialWeightsResult result = ProjectOntoBases(&samples, {&kGlossy, &kMatte}, MaterialWeightsOptions{});
  ASSERT_EQ(result.cells.size(), 1u);
  const CellWeights& cell = result.cells[0];
  ASSERT_TRUE(cell.fitted);
  EXPECT_EQ(cell.weights[0], 0.0);
  double ab = 0.0, aa = 0.0;
  for (const LocatedSample& s : samples) {
    const Eigen::Vector3d wi(s.sample.wi[0], s.sample.wi[1], s.sample.wi[2]);
    const Eigen::Vector3d wo(s.sample.wo[0], s.sample.wo[1], s.sample.wo[2]);
    const Eigen::Vector3d g = kGlossy.Eval(wi, wo), m = kMatte.Eval(wi, wo);
    for (int k = 0; k < 3; ++k) {
      const double mean = 0.5 * (g[k] + m[k]);
      ab += (m[k] / mean) * (s.sample.brdf[k] / mean);
      aa += (m[k] / mean) * (m[k] / mean);
    }
  }
  EXPECT_NEAR(cell.weights[1], ab / aa, 1e-6 * ab / aa);
}

TEST(MaterialWeights, AMaterialNoBasisSpansDoesNotFit) {
  std::vector<LocatedSample> samples;
  AddCell(1, 200, 1, [](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return kMatte.Eval(wi, wo); },
          &samples);
  // A green matte: no non-negative mix of the red-brown matte and the blue gloss has its colour.
  const LambertianBrdf green(Eigen::Vector3d(0.05, 0.6, 0.05));
  AddCell(2, 200, 2, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return green.Eval(wi, wo); },
          &samples);
  AddCell(3, 10, 3, [](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return kMatte.Eval(wi, wo); },
          &samples);  // too few samples to fit
  MaterialWeightsOptions options;
  const MaterialWeightsResult result = ProjectOntoBases(&samples, {&kGlossy, &kMatte}, options);
  ASSERT_EQ(result.cells.size(), 3u);
  EXPECT_TRUE(CellOf(result, 1).fits);
  EXPECT_FALSE(CellOf(result, 2).fits);
  EXPECT_FALSE(CellOf(result, 3).fitted);
  EXPECT_EQ(CellOf(result, 3).samples, 10u);
  EXPECT_EQ(result.cells_fitted, 2u);
  EXPECT_EQ(result.cells_not_fitting, 1u);
  EXPECT_DOUBLE_EQ(result.not_fitting_fraction, 0.5);
  const std::string brief = result.BriefReport(options);
  EXPECT_NE(brief.find("1 (50.0 %) fit no combination"), std::string::npos) << brief;
}

TEST(MaterialWeights, AChannelWithoutABasisValueIsNotUsed) {
  // A basis with no value (negative, a table's "no data") in red at every direction: the cell is fitted
  // on green and blue alone.
  class NoRed : public BrdfModel {
   public:
    Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override {
      Eigen::Vector3d f = kGlossy.Eval(wi, wo);
      f[0] = -1.0;
      return f;
    }
    nlohmann::json ToJson() const override { return kGlossy.ToJson(); }
    std::string ModelName() const override { return "ggx"; }
  } no_red;
  std::vector<LocatedSample> samples;
  AddCell(1, 100, 4, [](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
    return Eigen::Vector3d(0.5 * kGlossy.Eval(wi, wo) + 0.5 * kMatte.Eval(wi, wo));
  }, &samples);
  const MaterialWeightsResult result = ProjectOntoBases(&samples, {&no_red, &kMatte}, MaterialWeightsOptions{});
  const CellWeights& cell = result.cells[0];
  ASSERT_TRUE(cell.fitted);
  EXPECT_EQ(cell.usable, 200u);
  EXPECT_TRUE(std::isnan(cell.ratio[0]));
  EXPECT_NEAR(cell.weights[0], 0.5, 1e-5);
}

TEST(MaterialWeights, RefusesNoBasisAndBadOptions) {
  std::vector<LocatedSample> samples;
  EXPECT_THROW(ProjectOntoBases(&samples, {}, MaterialWeightsOptions{}), Error);
  MaterialWeightsOptions options;
  options.warn_fraction = 0.5;
  options.fail_fraction = 0.1;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_THROW(ProjectOntoBases(&samples, {&kMatte}, options), Error);
}

}  // namespace
}  // namespace ibrdf
