// The normal equations' kernel: every instruction-set version gives the bits of the plain point-by-point
// sums (the order the regression's outputs were recorded with).
#include "reconstruct/normal_accumulation.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace ibrdf {
namespace {

// Rows as the regression keeps them: weights in (0, 1], basis values of offsets in [-1, 1], log means;
// then the padding, filled with NaN (the kernel may read it but must not use it).
std::vector<double> Rows(size_t count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> rows(count * kNormalRowSize + kNormalRowPadding, std::nan(""));
  for (size_t p = 0; p < count; ++p) {
    double* row = rows.data() + p * kNormalRowSize;
    const double n = 1.0 + double(rng() % 40), t = 1.0 - std::abs(unit(rng));
    const double w = t * t * t;
    const double x = unit(rng), y = unit(rng), z = unit(rng);
    const double basis[kNormalCoefficients] = {1.0, x, y, z, x * x, y * y, z * z, x * y, x * z, y * z};
    row[kNormalSquaredWeight] = n * w * w;
    row[kNormalWeight] = n * w;
    for (int i = 0; i < kNormalCoefficients; ++i) row[kNormalBasis + i] = basis[i];
    for (int c = 0; c < 3; ++c) row[kNormalMean + c] = -3.0 + unit(rng);
  }
  return rows;
}

// The sums point by point, as the regression added them before the kernel existed.
void Reference(const std::vector<double>& rows, size_t count, double a[kNormalCoefficients][kNormalCoefficients],
               double b[kNormalCoefficients][3]) {
  for (int i = 0; i < kNormalCoefficients; ++i) {
    for (int j = i; j < kNormalCoefficients; ++j) a[i][j] = 0.0;
    for (int c = 0; c < 3; ++c) b[i][c] = 0.0;
  }
  for (size_t p = 0; p < count; ++p) {
    const double* row = rows.data() + p * kNormalRowSize;
    for (int i = 0; i < kNormalCoefficients; ++i) {
      const double wb = row[kNormalWeight] * row[kNormalBasis + i];
      for (int j = i; j < kNormalCoefficients; ++j) a[i][j] += wb * row[kNormalBasis + j];
      for (int c = 0; c < 3; ++c) b[i][c] += wb * row[kNormalMean + c];
    }
  }
}

TEST(NormalAccumulation, EveryVersionGivesThePointByPointBits) {
  int versions = 0;
  for (const char* isa : {"sse2", "avx2", "avx512f"}) {
    for (size_t count : {size_t(0), size_t(1), size_t(2), size_t(7), size_t(64), size_t(333), size_t(2000)}) {
      const std::vector<double> rows = Rows(count, 17 + count);
      double a[kNormalCoefficients][kNormalCoefficients], b[kNormalCoefficients][3];
      double want_a[kNormalCoefficients][kNormalCoefficients], want_b[kNormalCoefficients][3];
      Reference(rows, count, want_a, want_b);
      if (!AccumulateNormalEquationsWith(isa, rows.data(), count, a, b)) {
        std::printf("%s: not available on this processor or build; not compared\n", isa);
        break;
      }
      if (count == 0) ++versions;
      for (int i = 0; i < kNormalCoefficients; ++i) {
        for (int j = i; j < kNormalCoefficients; ++j) {
          ASSERT_EQ(std::memcmp(&a[i][j], &want_a[i][j], sizeof(double)), 0)
              << isa << " count " << count << " a[" << i << "][" << j << "] " << a[i][j] << " vs " << want_a[i][j];
        }
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(std::memcmp(&b[i][c], &want_b[i][c], sizeof(double)), 0)
              << isa << " count " << count << " b[" << i << "][" << c << "]";
        }
      }
    }
  }
  EXPECT_GE(versions, 1);  // the baseline always runs
  // The dispatched version is one of them.
  const std::string chosen = NormalAccumulationIsa();
  EXPECT_TRUE(chosen == "sse2" || chosen == "avx2" || chosen == "avx512f") << chosen;
  std::printf("dispatched: %s\n", chosen.c_str());
}

TEST(NormalAccumulation, UnknownInstructionSetIsRefused) {
  const std::vector<double> rows = Rows(3, 1);
  double a[kNormalCoefficients][kNormalCoefficients], b[kNormalCoefficients][3];
  EXPECT_FALSE(AccumulateNormalEquationsWith("neon", rows.data(), 3, a, b));
}

}  // namespace
}  // namespace ibrdf
