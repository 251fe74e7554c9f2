// Neighbour queries over scan points: a nanoflann kd-tree (nanoflann stays in point_index.cc).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

namespace ibrdf {

class PointIndex {
 public:
  // Indexes `points` (kept by reference: they must outlive the index). Coordinates are centred on
  // their centroid inside the index, so queries far from the origin keep their precision.
  explicit PointIndex(const std::vector<Eigen::Vector3d>& points);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  // Indices of the points within `radius_m` of `query` (the query point itself included when it is
  // one of the points), in no particular order.
  void RadiusSearch(const Eigen::Vector3d& query, double radius_m, std::vector<int>* indices) const;

  // The k nearest points (fewer when there are fewer points), nearest first, and their distances.
  void Nearest(const Eigen::Vector3d& query, int k, std::vector<int>* indices, std::vector<double>* distances_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The median distance from a point to its nearest other point, over up to `max_samples` points taken
// evenly (0 when there are fewer than 2 points).
double MedianPointSpacing(const std::vector<Eigen::Vector3d>& points, size_t max_samples = 20000);

}  // namespace ibrdf
