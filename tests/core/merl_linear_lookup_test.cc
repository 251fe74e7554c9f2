// The linear lookup of a MERL table (core/merl_brdf.h, MerlLookup::kLinear), the one the report draws
// its curves and renders with: exact at cell centres, linear between them, unmeasured neighbours left
// out, no value where the reader's own cell has no data.
#include "core/merl_brdf.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"

namespace ibrdf {
namespace {

// A table whose cells hold a linear function of the cell indices (so interpolation is exact).
MerlTable LinearTable() {
  MerlTable table;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        const double v = 0.1 + 0.01 * i + 0.002 * j;  // independent of phi_d: periodic without a seam
        table.SetCell(MerlFlatIndex(i, j, k), Eigen::Vector3d(v, 2 * v, 3 * v));
      }
    }
  }
  return table;
}

void Directions(double theta_h, double theta_d, double phi_d, Eigen::Vector3d* wi, Eigen::Vector3d* wo) {
  HalfDiffAngles a;
  a.theta_h = theta_h;
  a.theta_d = theta_d;
  a.phi_d = phi_d;
  FromHalfDiff(a, wi, wo);
}

// The table's linear reading at (wi, wo).
Eigen::Vector3d Linear(const MerlTable& table, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  return MerlBrdf(table, "t.binary", MerlLookup::kLinear).Lookup(wi, wo);
}

TEST(MerlLinearLookup, ExactAtCellCentresAndLinearBetween) {
  const MerlTable table = LinearTable();
  Eigen::Vector3d wi, wo;
  // The centre of cell (i, j): theta_h = ((i + 0.5) / 90)^2 pi / 2, theta_d = (j + 0.5) / 90 pi / 2.
  const auto theta_h = [](double u) { return (u / 90.0) * (u / 90.0) * M_PI / 2.0; };
  const auto theta_d = [](double v) { return v / 90.0 * M_PI / 2.0; };
  Directions(theta_h(20.5), theta_d(30.5), 1.0, &wi, &wo);
  const Eigen::Vector3d at_centre = Linear(table, wi, wo);
  EXPECT_NEAR(at_centre[0], 0.1 + 0.01 * 20 + 0.002 * 30, 1e-6);
  EXPECT_NEAR(at_centre[2], 3 * at_centre[0], 1e-6);
  // Halfway between centres in both axes: the mean, where the reader's lookup steps.
  Directions(theta_h(21.0), theta_d(31.0), 1.0, &wi, &wo);
  EXPECT_NEAR(Linear(table, wi, wo)[0], 0.1 + 0.01 * 20.5 + 0.002 * 30.5, 1e-6);
  EXPECT_NEAR(table.Lookup(wi, wo)[0], 0.1 + 0.01 * 21 + 0.002 * 31, 1e-6);  // the cell, a step away
}

TEST(MerlLinearLookup, UnmeasuredNeighboursAreLeftOutAndAnUnmeasuredCellHasNoValue) {
  MerlTable table = LinearTable();
  Eigen::Vector3d wi, wo;
  const auto theta_h = [](double u) { return (u / 90.0) * (u / 90.0) * M_PI / 2.0; };
  // A quarter of the way from cell 40's centre to cell 41's: cell 40 is the reader's own.
  Directions(theta_h(40.75), 20.5 / 90.0 * M_PI / 2.0, M_PI / 2.0, &wi, &wo);
  EXPECT_NEAR(Linear(table, wi, wo)[0], 0.1 + 0.01 * 40.25 + 0.002 * 20, 1e-6);
  for (int k = 0; k < kMerlPhiD; ++k) table.SetUnmeasured(MerlFlatIndex(41, 20, k));
  // Cell 40 remains: its value, not a blend with the missing one.
  EXPECT_NEAR(Linear(table, wi, wo)[0], 0.1 + 0.01 * 40 + 0.002 * 20, 1e-6);
  // The reader's own cell without data: no value, although its neighbour, cell 41, is measured.
  MerlTable holed = LinearTable();
  for (int k = 0; k < kMerlPhiD; ++k) holed.SetUnmeasured(MerlFlatIndex(40, 20, k));
  EXPECT_LT(Linear(holed, wi, wo)[0], 0.0);
}

}  // namespace
}  // namespace ibrdf
