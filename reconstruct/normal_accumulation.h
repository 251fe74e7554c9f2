// The sums of a local quadratic fit's normal equations from the kept rows of its kernel points
// (reconstruct/local_regression.cc): the regression's innermost loop, in the widest vector instructions
// the processor has (AVX-512, AVX2, else the build's SSE2), chosen once at run time.
//
// Vectors run across the elements of one row of the normal matrix (and the right-hand sides), never
// across points, and no multiply-add is fused (the file is compiled with -ffp-contract=off): every
// element is summed over the points in the order they are given, with the same products, so all three
// versions give the same bits (docs/decisions.md, "Reconstruct speed: the tabulation's kernel").
#pragma once

#include <cstddef>

namespace ibrdf {

// One kept row per kernel point: count * w^2, count * w, the 10 quadratic basis values
// (1, x, y, z, x^2, y^2, z^2, xy, xz, yz) and the point's 3 mean values, kNormalRowSize doubles.
constexpr int kNormalCoefficients = 10;
constexpr int kNormalSquaredWeight = 0, kNormalWeight = 1, kNormalBasis = 2;
constexpr int kNormalMean = kNormalBasis + kNormalCoefficients;
constexpr int kNormalRowSize = kNormalMean + 3;
// Doubles after the last row that the kernel may read (and discard): the buffer holds
// count * kNormalRowSize + kNormalRowPadding doubles.
constexpr int kNormalRowPadding = 16;

// a[i][j] = sum_p w_p b_pi b_pj for j >= i (the upper triangle; the rest is left as it is) and
// b[i][c] = sum_p w_p b_pi m_pc over the `count` rows at `rows`, p in order. The rows are followed by
// kNormalRowPadding readable doubles (any values).
void AccumulateNormalEquations(const double* rows, size_t count, double a[kNormalCoefficients][kNormalCoefficients],
                               double b[kNormalCoefficients][3]);

// The instruction set AccumulateNormalEquations uses here: "avx512f", "avx2" or "sse2".
const char* NormalAccumulationIsa();

// As AccumulateNormalEquations with the version for `isa` ("avx512f", "avx2", "sse2"); false (nothing
// written) where this processor or build does not have it. For tests that compare the versions.
bool AccumulateNormalEquationsWith(const char* isa, const double* rows, size_t count,
                                   double a[kNormalCoefficients][kNormalCoefficients],
                                   double b[kNormalCoefficients][3]);

}  // namespace ibrdf
