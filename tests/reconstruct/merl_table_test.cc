// The MERL binary format: the reader's indexing, and a write / read / evaluate round trip that is
// identical to the last bit at bin centres.
#include "reconstruct/merl_table.h"

#include <cstring>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/npy.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::ScratchDir;

TEST(MerlTable, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(TabulateOptions().Check(&why)) << why;
}

TEST(MerlTable, CellCentresMapBackToTheirCells) {
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; j += 7) {
      for (int k = 0; k < kMerlPhiD; k += 11) {
        const HalfDiffAngles a = MerlCellCentre(i, j, k);
        ASSERT_EQ(MerlThetaHalfIndex(a.theta_h), i);
        ASSERT_EQ(MerlThetaDiffIndex(a.theta_d), j);
        ASSERT_EQ(MerlPhiDiffIndex(a.phi_d), k);
      }
    }
  }
  EXPECT_EQ(MerlPhiDiffIndex(-0.5 * M_PI / 180.0), 179);  // reciprocity fold
}

TEST(MerlTable, RoundTripIsBitIdenticalAtBinCentres) {
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const auto samples = testing::SessionSamples(*material, CameraEffects::None(), 8, 200, 150);
  const LocalRegression regression(samples, LocalRegressionOptions());
  TabulateSummary summary;
  std::vector<float> ess;
  const MerlTable table = TabulateMerl(regression, TabulateOptions(), &summary, &ess);
  ASSERT_TRUE(summary.success);
  EXPECT_GT(summary.domain.measured + summary.domain.interpolated, 500000u);
  EXPECT_GT(summary.cells_below_horizon, 0u);
  ScratchDir dir;
  WriteMerl(dir / "t.binary", table);
  const MerlTable back = ReadMerl(dir / "t.binary");
  ASSERT_EQ(0, std::memcmp(back.stored().data(), table.stored().data(), table.stored().size() * sizeof(double)));
  // The file layout: three int32 then doubles, red first.
  std::ifstream in(dir / "t.binary", std::ios::binary);
  int32_t dims[3];
  in.read(reinterpret_cast<char*>(dims), sizeof(dims));
  EXPECT_EQ(dims[0], 90);
  EXPECT_EQ(dims[1], 90);
  EXPECT_EQ(dims[2], 180);
  size_t compared = 0;
  for (int i = 0; i < kMerlThetaH; i += 3) {
    for (int j = 0; j < kMerlThetaD; j += 3) {
      for (int k = 0; k < kMerlPhiD; k += 5) {
        const size_t flat = MerlFlatIndex(i, j, k);
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        const Eigen::Vector3d looked_up = back.Lookup(wi, wo);
        ASSERT_EQ(looked_up, table.Cell(flat));  // bit for bit
        if (!table.Measured(flat)) {
          EXPECT_LT(looked_up[0], 0.0);
          continue;
        }
        const Estimate e = regression.Evaluate(MerlCellCentre(i, j, k));
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(looked_up[c], e.value[c], 1e-12 * std::max(1.0, e.value[c]));
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 5000u);
  // The .npy export reads back to the same values.
  WriteNpyArray(dir / "t.npy", MerlToArray(table), {90, 90, 180, 3});
  std::vector<size_t> shape;
  const std::vector<double> array = ReadNpyArray(dir / "t.npy", &shape);
  ASSERT_EQ(shape, (std::vector<size_t>{90, 90, 180, 3}));
  EXPECT_EQ(array, MerlToArray(table));
}

TEST(MerlTable, BadFilesAreClearErrors) {
  ScratchDir dir;
  {
    std::ofstream out(dir / "bad.binary", std::ios::binary);
    const int32_t dims[3] = {90, 90, 360};
    out.write(reinterpret_cast<const char*>(dims), sizeof(dims));
  }
  EXPECT_THROW(ReadMerl(dir / "bad.binary"), Error);
  EXPECT_THROW(ReadMerl(dir / "missing.binary"), Error);
}

// A NaN in a table must not be read silently: an Error naming the file and the value's index.
TEST(MerlTable, NonFiniteValueIsAnError) {
  ScratchDir dir;
  MerlTable table;
  table.stored()[12345] = std::numeric_limits<double>::quiet_NaN();
  WriteMerl(dir / "nan.binary", table);
  try {
    ReadMerl(dir / "nan.binary");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir / "nan.binary: value 12345 is not finite"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
