// Tests of core/merl_format.h: a MERL table round-trips, and a table holding a value no BRDF has is
// refused by name instead of turning into NaN pixels downstream.
#include "core/merl_format.h"

#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

MerlTable Lambertian() {
  MerlTable table;
  for (size_t flat = 0; flat < kMerlCells; ++flat) table.SetCell(flat, Eigen::Vector3d(0.2, 0.2, 0.2));
  return table;
}

TEST(MerlFormat, RoundTrips) {
  testing::ScratchDir dir;
  const MerlTable table = Lambertian();
  WriteMerl(dir / "t.binary", table);
  const MerlTable read = ReadMerl(dir / "t.binary");
  EXPECT_EQ(read.stored(), table.stored());
  EXPECT_NEAR(read.Cell(1234)[1], 0.2, 1e-12);
}

TEST(MerlFormat, AbsurdValuesAreAnErrorNamingTheFile) {
  testing::ScratchDir dir;
  for (const double absurd : {1e300, -1e300, 1e20}) {
    SCOPED_TRACE(absurd);
    MerlTable table = Lambertian();
    table.stored()[kMerlCells + 77] = absurd;  // green, cell 77
    const std::string path = dir / "absurd.binary";
    WriteMerl(path, table);
    try {
      ReadMerl(path);
      ADD_FAILURE() << "accepted a table holding " << absurd;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find("green, cell 77"), std::string::npos) << message;
    }
  }
}

// Unmeasured cells (-1) and a very specular peak stay readable.
TEST(MerlFormat, UnmeasuredCellsAndSpecularPeaksAreAccepted) {
  testing::ScratchDir dir;
  MerlTable table = Lambertian();
  table.SetUnmeasured(5);
  table.SetCell(6, Eigen::Vector3d(5e4, 5e4, 5e4));
  WriteMerl(dir / "peak.binary", table);
  const MerlTable read = ReadMerl(dir / "peak.binary");
  EXPECT_FALSE(read.Measured(5));
  EXPECT_NEAR(read.Cell(6)[2], 5e4, 1e-6);
}

}  // namespace
}  // namespace ibrdf
