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

// Eight doubles, one AVX-512 register.
typedef double Vector8 __attribute__((vector_size(64)));

// Row I's 13 - I sums as one or two Vector8 (lanes beyond them hold discarded sums of whatever follows
// in the buffer: it is padded, kNormalRowPadding).
template <int I>
constexpr int kVectors = kNormalRowSize - kNormalBasis - I > 8 ? 2 : 1;

[[gnu::target("avx512f"), gnu::always_inline]] inline Vector8 Load8(const double* p) {
  Vector8 v;
  __builtin_memcpy(&v, p, sizeof(v));
  return v;
}

template <int I>
[[gnu::target("avx512f"), gnu::always_inline]] inline void AddRow512(const double* row, Vector8 (&sum)[2]) {
  const double wb = row[kNormalWeight] * row[kNormalBasis + I];
  const Vector8 w = {wb, wb, wb, wb, wb, wb, wb, wb};
  sum[0] += w * Load8(row + kNormalBasis + I);
  if constexpr (kVectors<I> == 2) sum[1] += w * Load8(row + kNormalBasis + I + 8);
}

template <int I>
[[gnu::target("avx512f"), gnu::always_inline]] inline void StoreRow512(
    const Vector8 (&sum)[2], double a[kNormalCoefficients][kNormalCoefficients], double b[kNormalCoefficients][3]) {
  double lanes[16];
  __builtin_memcpy(lanes, &sum[0], sizeof(Vector8));
  if constexpr (kVectors<I> == 2) __builtin_memcpy(lanes + 8, &sum[1], sizeof(Vector8));
  for (int j = 0; j < kNormalCoefficients - I; ++j) a[I][I + j] = lanes[j];
  for (int c = 0; c < 3; ++c) b[I][c] = lanes[kNormalCoefficients - I + c];
}

template <int... I>
[[gnu::target("avx512f"), gnu::always_inline]] inline void Accumulate512(
    const double* rows, size_t count, double a[kNormalCoefficients][kNormalCoefficients],
    double b[kNormalCoefficients][3]) {
  Vector8 sums[sizeof...(I)][2] = {};
  for (size_t p = 0; p < count; ++p) {
    const double* row = rows + p * kNormalRowSize;
    (AddRow512<I>(row, sums[I]), ...);
  }
  (StoreRow512<I>(sums[I], a, b), ...);
}

// One pass over the points with all 85 sums in registers (15 of the 32 AVX-512 registers), each row
// read once: every sum still adds the points' products in their order.
[[gnu::target("avx512f")]] void AccumulateAvx512(const double* rows, size_t count,
                                                 double a[kNormalCoefficients][kNormalCoefficients],
                                                 double b[kNormalCoefficients][3]) {
  Accumulate512<0, 1, 2, 3, 4, 5, 6, 7, 8, 9>(rows, count, a, b);
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
