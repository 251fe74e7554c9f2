// Order statistics shared by every stage: one percentile convention for the whole tool.
//
// Convention (nearest rank, rounded): the q-th percentile of n values is the value of rank
// round(q * (n - 1)) in ascending order (rank 0 the smallest). No interpolation, so every percentile
// is one of the values; the median is the value of rank n / 2 (for even n the upper of the two middle
// values). Empty input gives 0. NaN values are not allowed (IBRDF_CHECK).
#pragma once

#include <cstddef>
#include <vector>

namespace ibrdf {

// The q-th percentile (q in [0, 1]) of `values` by the convention above. Takes a copy it may reorder.
double Percentile(std::vector<double> values, double q);
float Percentile(std::vector<float> values, double q);

// The same, reordering `values` in place (no copy; for large vectors).
double PercentileInPlace(std::vector<double>* values, double q);
float PercentileInPlace(std::vector<float>* values, double q);

// Percentile(values, 0.5).
double Median(std::vector<double> values);

// The rank that Percentile picks among n values: round(q * (n - 1)). n must be positive.
size_t PercentileRank(size_t n, double q);

}  // namespace ibrdf
