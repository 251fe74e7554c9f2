// A MERL table against the truth (reconstruct/reconstruction_error.h): several comparisons at once
// (the truth evaluated once, TBB-parallel) give what a plain serial loop over the cells gives, for
// each domain; one comparison alone is the same as the first of several.
#include "reconstruct/reconstruction_error.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/statistics.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

// The reference: every cell with theta_i, theta_e <= 80 deg, in flat order, scored where the table has
// data and the domain (if any) is non-zero.
ReconstructionError Reference(const MerlTable& table, const BrdfModel& truth, const std::vector<uint8_t>* domain) {
  ReconstructionError error;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<double> abs[3];
  const double cos_limit = std::cos(80.0 * M_PI / 180.0);
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        if (!(wi.z() >= cos_limit && wo.z() >= cos_limit)) continue;
        const size_t flat = MerlFlatIndex(i, j, k);
        if (!table.Measured(flat) || (domain && !(*domain)[flat])) {
          ++error.outside;
          continue;
        }
        const Eigen::Vector3d t = truth.Eval(wi, wo);
        const Eigen::Vector3d rel = (table.Cell(flat) - t).cwiseQuotient(t);
        sum += rel.cwiseAbs2();
        for (int c = 0; c < 3; ++c) abs[c].push_back(std::abs(rel[c]));
        ++error.points;
      }
    }
  }
  error.rel_rms = (sum / double(error.points)).cwiseSqrt();
  for (int c = 0; c < 3; ++c) error.median[c] = PercentileInPlace(&abs[c], 0.5);
  return error;
}

TEST(CompareTableWithTruth, SeveralDomainsAtOnceEqualASerialLoopForEach) {
  const auto truth = LoadMaterial(testing::MaterialPath("bluepaint"));
  // The truth with a few per cent of noise, every fifth cell without data; two domains.
  MerlTable table;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<uint8_t> half(kMerlCells), sparse(kMerlCells);
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        const size_t flat = MerlFlatIndex(i, j, k);
        half[flat] = k < kMerlPhiD / 2;
        sparse[flat] = (flat % 7) == 0;
        if (flat % 5 == 0) continue;
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        if (wi.z() <= 0.0 || wo.z() <= 0.0) continue;
        table.SetCell(flat, truth->Eval(wi, wo) * (1.0 + noise(rng)));
      }
    }
  }
  const std::vector<const std::vector<uint8_t>*> domains = {&half, nullptr, &sparse};
  const std::vector<ReconstructionError> errors = CompareTableWithTruth(table, *truth, 80.0, domains);
  ASSERT_EQ(errors.size(), 3u);
  for (size_t d = 0; d < domains.size(); ++d) {
    SCOPED_TRACE(d);
    const ReconstructionError reference = Reference(table, *truth, domains[d]);
    EXPECT_EQ(errors[d].points, reference.points);
    EXPECT_EQ(errors[d].outside, reference.outside);
    EXPECT_GT(errors[d].points, 10000u);
    for (int c = 0; c < 3; ++c) {
      EXPECT_DOUBLE_EQ(errors[d].rel_rms[c], reference.rel_rms[c]);
      EXPECT_EQ(errors[d].median[c], reference.median[c]);
      EXPECT_NEAR(errors[d].rel_rms[c], 0.02, 0.002);  // the noise put in
    }
  }
  const ReconstructionError alone = CompareTableWithTruth(table, *truth, 80.0, &sparse);
  EXPECT_EQ(alone.points, errors[2].points);
  EXPECT_EQ(alone.rel_rms, errors[2].rel_rms);
  EXPECT_EQ(alone.p95, errors[2].p95);
}

}  // namespace
}  // namespace ibrdf
