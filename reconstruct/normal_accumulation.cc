#include "reconstruct/normal_accumulation.h"

#include <cstring>

namespace ibrdf {
namespace {

// Row I: the upper-triangle elements a[I][I..9] and b[I][0..2] are the last 13 - I doubles of each kept
// row times w b_I, contiguous in the row (the basis from index I, then the means).
template <int I>
[[gnu::always_inline]] inline void AccumulateRow(const double* rows, size_t count,
                                                 double a[kNormalCoefficients][kNormalCoefficients],
                                                 double b[kNormalCoefficients][3]) {
  constexpr int kSums = kNormalRowSize - kNormalBasis - I;  // 10 - I matrix elements, then 3 right-hand sides
  double sum[kSums] = {};
  for (size_t p = 0; p < count; ++p) {
    const double* row = rows + p * kNormalRowSize;
    const double wb = row[kNormalWeight] * row[kNormalBasis + I];
    for (int j = 0; j < kSums; ++j) sum[j] += wb * row[kNormalBasis + I + j];
  }
  for (int j = 0; j < kNormalCoefficients - I; ++j) a[I][I + j] = sum[j];
  for (int c = 0; c < 3; ++c) b[I][c] = sum[kNormalCoefficients - I + c];
}

template <int... I>
[[gnu::always_inline]] inline void AccumulateRows(const double* rows, size_t count,
                                                  double a[kNormalCoefficients][kNormalCoefficients],
                                                  double b[kNormalCoefficients][3]) {
  (AccumulateRow<I>(rows, count, a, b), ...);
}

#define IBRDF_ACCUMULATE_BODY AccumulateRows<0, 1, 2, 3, 4, 5, 6, 7, 8, 9>(rows, count, a, b)

void AccumulateBaseline(const double* rows, size_t count, double a[kNormalCoefficients][kNormalCoefficients],
                        double b[kNormalCoefficients][3]) {
  IBRDF_ACCUMULATE_BODY;
}

#if defined(__x86_64__) && defined(__GNUC__)
#define IBRDF_ACCUMULATE_DISPATCH 1
[[gnu::target("avx2")]] void AccumulateAvx2(const double* rows, size_t count,
                                            double a[kNormalCoefficients][kNormalCoefficients],
                                            double b[kNormalCoefficients][3]) {
  IBRDF_ACCUMULATE_BODY;
}

[[gnu::target("avx512f")]] void AccumulateAvx512(const double* rows, size_t count,
                                                 double a[kNormalCoefficients][kNormalCoefficients],
                                                 double b[kNormalCoefficients][3]) {
  IBRDF_ACCUMULATE_BODY;
}
#endif

using Kernel = void (*)(const double*, size_t, double[kNormalCoefficients][kNormalCoefficients],
                        double[kNormalCoefficients][3]);

struct Choice {
  Kernel kernel;
  const char* isa;
};

Choice Choose() {
#ifdef IBRDF_ACCUMULATE_DISPATCH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return {AccumulateAvx512, "avx512f"};
  if (__builtin_cpu_supports("avx2")) return {AccumulateAvx2, "avx2"};
#endif
  return {AccumulateBaseline, "sse2"};
}

const Choice& Chosen() {
  static const Choice choice = Choose();
  return choice;
}

}  // namespace

void AccumulateNormalEquations(const double* rows, size_t count, double a[kNormalCoefficients][kNormalCoefficients],
                               double b[kNormalCoefficients][3]) {
  Chosen().kernel(rows, count, a, b);
}

const char* NormalAccumulationIsa() { return Chosen().isa; }

bool AccumulateNormalEquationsWith(const char* isa, const double* rows, size_t count,
                                   double a[kNormalCoefficients][kNormalCoefficients],
                                   double b[kNormalCoefficients][3]) {
  Kernel kernel = nullptr;
  if (std::strcmp(isa, "sse2") == 0) kernel = AccumulateBaseline;
#ifdef IBRDF_ACCUMULATE_DISPATCH
  __builtin_cpu_init();
  if (std::strcmp(isa, "avx2") == 0 && __builtin_cpu_supports("avx2")) kernel = AccumulateAvx2;
  if (std::strcmp(isa, "avx512f") == 0 && __builtin_cpu_supports("avx512f")) kernel = AccumulateAvx512;
#endif
  if (!kernel) return false;
  kernel(rows, count, a, b);
  return true;
}

}  // namespace ibrdf
