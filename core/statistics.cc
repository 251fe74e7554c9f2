#include "core/statistics.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace ibrdf {
namespace {

template <class T>
T PercentileOf(std::vector<T>* values, double q) {
  if (values->empty()) return T(0);
  const size_t k = PercentileRank(values->size(), q);
  std::nth_element(values->begin(), values->begin() + static_cast<std::ptrdiff_t>(k), values->end());
  return (*values)[k];
}

}  // namespace

size_t PercentileRank(size_t n, double q) {
  IBRDF_CHECK(n > 0);
  IBRDF_CHECK(q >= 0.0 && q <= 1.0) << "q = " << q;
  return std::min(n - 1, static_cast<size_t>(q * double(n - 1) + 0.5));
}

double Percentile(std::vector<double> values, double q) { return PercentileOf(&values, q); }
float Percentile(std::vector<float> values, double q) { return PercentileOf(&values, q); }
double PercentileInPlace(std::vector<double>* values, double q) { return PercentileOf(values, q); }
float PercentileInPlace(std::vector<float>* values, double q) { return PercentileOf(values, q); }
double Median(std::vector<double> values) { return PercentileOf(&values, 0.5); }

}  // namespace ibrdf
