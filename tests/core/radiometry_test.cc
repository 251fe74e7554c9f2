// Tests of core/radiometry.h: the camera response curves that turn file values into linear signal.
#include "core/radiometry.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace ibrdf {
namespace {

Response Table(std::vector<double> table) {
  Response response;
  response.kind = Response::Kind::kTable;
  response.table = std::move(table);
  return response;
}

Response Gamma(double gamma) {
  Response response;
  response.kind = Response::Kind::kGamma;
  response.gamma = gamma;
  return response;
}

// IEC 61966-2-1 at known points: the ends, mid-grey (0.5 -> 0.2140) and the linear toe.
TEST(Srgb, KnownValues) {
  EXPECT_EQ(SrgbToLinear(0.0), 0.0);
  EXPECT_NEAR(SrgbToLinear(1.0), 1.0, 1e-15);
  EXPECT_NEAR(SrgbToLinear(0.5), 0.21404114048223255, 1e-15);
  EXPECT_NEAR(SrgbToLinear(0.2), 0.033104766570885055, 1e-15);
  EXPECT_NEAR(SrgbToLinear(0.02), 0.02 / 12.92, 1e-17);
  EXPECT_NEAR(LinearToSrgb(0.001), 0.01292, 1e-15);
  EXPECT_NEAR(LinearToSrgb(1.0), 1.0, 1e-15);
}

// The two branches of the curve meet at the breakpoint (to the standard's 4-digit constants).
TEST(Srgb, ContinuousAtBreakpoint) {
  const double below = SrgbToLinear(0.04045 - 1e-12), above = SrgbToLinear(0.04045 + 1e-12);
  EXPECT_NEAR(below, above, 1e-8);
  EXPECT_NEAR(LinearToSrgb(0.0031308 - 1e-12), LinearToSrgb(0.0031308 + 1e-12), 1e-7);
}

// Encoding and decoding invert each other over [0, 1], and both are strictly increasing.
TEST(Srgb, RoundTripAndMonotone) {
  double previous = -1.0;
  for (int i = 0; i <= 10000; ++i) {
    const double encoded = i / 10000.0;
    const double linear = SrgbToLinear(encoded);
    EXPECT_NEAR(LinearToSrgb(linear), encoded, 1e-12) << encoded;
    EXPECT_GT(linear, previous) << encoded;
    previous = linear;
  }
}

TEST(Response, DefaultIsLinearAndValid) {
  const Response response;
  EXPECT_EQ(response.kind, Response::Kind::kLinear);
  std::string why;
  EXPECT_TRUE(response.Check(&why)) << why;
  EXPECT_EQ(response.ToLinear(0.37), 0.37);
  EXPECT_EQ(response.FromLinear(0.37), 0.37);
  EXPECT_EQ(response.Describe(), "linear");
}

TEST(Response, SrgbKindUsesTheStandardCurve) {
  Response response;
  response.kind = Response::Kind::kSrgb;
  EXPECT_EQ(response.ToLinear(0.5), SrgbToLinear(0.5));
  EXPECT_EQ(response.FromLinear(0.2), LinearToSrgb(0.2));
  EXPECT_EQ(response.Describe(), "srgb");
}

// file = linear^(1/gamma): ToLinear(v) = v^gamma, round trip, and no NaN for negative values.
TEST(Response, GammaCurve) {
  const Response response = Gamma(2.2);
  EXPECT_NEAR(response.ToLinear(0.5), std::pow(0.5, 2.2), 1e-15);
  EXPECT_NEAR(response.FromLinear(std::pow(0.5, 2.2)), 0.5, 1e-15);
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    EXPECT_NEAR(response.FromLinear(response.ToLinear(v)), v, 1e-12) << v;
  }
  EXPECT_EQ(response.ToLinear(-0.01), 0.0);
  EXPECT_EQ(response.FromLinear(-0.01), 0.0);
  EXPECT_EQ(response.Describe().rfind("gamma 2.2", 0), 0u) << response.Describe();
}

// A measured table: linear values at file values 0, 1/3, 2/3, 1, linearly interpolated.
TEST(Response, TableInterpolatesLinearly) {
  const Response response = Table({0.0, 0.1, 0.4, 1.0});
  std::string why;
  ASSERT_TRUE(response.Check(&why)) << why;
  EXPECT_NEAR(response.ToLinear(0.0), 0.0, 1e-15);
  EXPECT_NEAR(response.ToLinear(1.0 / 3), 0.1, 1e-15);
  EXPECT_NEAR(response.ToLinear(2.0 / 3), 0.4, 1e-15);
  EXPECT_NEAR(response.ToLinear(1.0), 1.0, 1e-15);
  EXPECT_NEAR(response.ToLinear(1.0 / 6), 0.05, 1e-15);
  EXPECT_NEAR(response.ToLinear(0.5), 0.25, 1e-15);
  EXPECT_NEAR(response.ToLinear(5.0 / 6), 0.7, 1e-15);
  // Outside [0, 1] the file value is clamped.
  EXPECT_NEAR(response.ToLinear(-0.5), 0.0, 1e-15);
  EXPECT_NEAR(response.ToLinear(1.5), 1.0, 1e-15);
  EXPECT_EQ(response.Describe(), "table (4 entries)");
}

// The table's inverse: FromLinear(ToLinear(v)) = v, and the table's own entries map to their knots.
TEST(Response, TableInverse) {
  const Response response = Table({0.01, 0.05, 0.2, 0.35, 0.9, 1.2});
  double previous = -1.0;
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    const double linear = response.ToLinear(v);
    EXPECT_GT(linear, previous) << v;
    previous = linear;
    EXPECT_NEAR(response.FromLinear(linear), v, 1e-12) << v;
  }
  for (size_t k = 0; k < response.table.size(); ++k) {
    EXPECT_NEAR(response.FromLinear(response.table[k]), k / 5.0, 1e-15) << k;
  }
  // Linear values beyond the table clamp to the ends.
  EXPECT_EQ(response.FromLinear(0.0), 0.0);
  EXPECT_EQ(response.FromLinear(5.0), 1.0);
}

// A two-entry table is a straight line from table[0] to table[1].
TEST(Response, TwoEntryTable) {
  const Response response = Table({0.0, 2.0});
  std::string why;
  ASSERT_TRUE(response.Check(&why)) << why;
  EXPECT_NEAR(response.ToLinear(0.25), 0.5, 1e-15);
  EXPECT_NEAR(response.FromLinear(1.5), 0.75, 1e-15);
}

// A response must be invertible: tables strictly increasing with at least two entries.
TEST(Response, CheckRejectsNonIncreasingTables) {
  std::string why;
  EXPECT_FALSE(Table({0.0, 0.5, 0.5, 1.0}).Check(&why));
  EXPECT_NE(why.find("increasing"), std::string::npos) << why;
  EXPECT_FALSE(Table({0.0, 0.6, 0.5, 1.0}).Check(&why));
  EXPECT_FALSE(Table({1.0, 0.0}).Check(&why));
  EXPECT_FALSE(Table({0.0, std::numeric_limits<double>::quiet_NaN(), 1.0}).Check(&why));
  EXPECT_FALSE(Table({0.5}).Check(&why));
  EXPECT_FALSE(Table({}).Check(&why));
  why.clear();
  EXPECT_TRUE(Table({0.0, 1e-9, 1.0}).Check(&why)) << why;
}

TEST(Response, CheckRejectsBadGamma) {
  std::string why;
  EXPECT_FALSE(Gamma(0.0).Check(&why));
  EXPECT_FALSE(Gamma(-2.2).Check(&why));
  EXPECT_FALSE(Gamma(std::numeric_limits<double>::quiet_NaN()).Check(&why));
  EXPECT_FALSE(Gamma(std::numeric_limits<double>::infinity()).Check(&why));
  EXPECT_TRUE(Gamma(1.8).Check(&why));
}

}  // namespace
}  // namespace ibrdf
