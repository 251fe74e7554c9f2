#include "scan/point_index.h"

#include "core/statistics.h"

#include <algorithm>

#include <nanoflann.hpp>

#include "scan/scan_mesh.h"

namespace ibrdf {

struct PointIndex::Impl {
  // nanoflann's dataset interface over centred copies of the points.
  struct Cloud {
    std::vector<Eigen::Vector3d> centred;
    size_t kdtree_get_point_count() const { return centred.size(); }
    double kdtree_get_pt(size_t i, size_t dim) const { return centred[i][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, int>;

  Eigen::Vector3d centre;
  Cloud cloud;
  std::unique_ptr<Tree> tree;
};

PointIndex::PointIndex(const std::vector<Eigen::Vector3d>& points) : impl_(std::make_unique<Impl>()) {
  impl_->centre = Centroid(points);
  impl_->cloud.centred.reserve(points.size());
  for (const Eigen::Vector3d& p : points) impl_->cloud.centred.push_back(p - impl_->centre);
  impl_->tree = std::make_unique<Impl::Tree>(3, impl_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  impl_->tree->buildIndex();
}

PointIndex::~PointIndex() = default;

void PointIndex::RadiusSearch(const Eigen::Vector3d& query, double radius_m, std::vector<int>* indices) const {
  indices->clear();
  if (impl_->cloud.centred.empty()) return;
  const Eigen::Vector3d q = query - impl_->centre;
  std::vector<std::pair<int, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = false;
  impl_->tree->radiusSearch(q.data(), radius_m * radius_m, matches, params);
  indices->reserve(matches.size());
  for (const auto& m : matches) indices->push_back(m.first);
}

void PointIndex::Nearest(const Eigen::Vector3d& query, int k, std::vector<int>* indices,
                         std::vector<double>* distances_m) const {
  const size_t n = std::min<size_t>(static_cast<size_t>(std::max(k, 0)), impl_->cloud.centred.size());
  indices->assign(n, -1);
  distances_m->assign(n, 0.0);
  if (n == 0) return;
  const Eigen::Vector3d q = query - impl_->centre;
  std::vector<double> squared(n);
  const size_t found = impl_->tree->knnSearch(q.data(), n, indices->data(), squared.data());
  indices->resize(found);
  distances_m->resize(found);
  for (size_t i = 0; i < found; ++i) (*distances_m)[i] = std::sqrt(squared[i]);
}

double MedianPointSpacing(const std::vector<Eigen::Vector3d>& points, size_t max_samples) {
  if (points.size() < 2) return 0.0;
  const PointIndex index(points);
  const size_t step = std::max<size_t>(1, points.size() / std::max<size_t>(1, max_samples));
  std::vector<double> spacing;
  std::vector<int> indices;
  std::vector<double> distances;
  for (size_t i = 0; i < points.size(); i += step) {
    index.Nearest(points[i], 2, &indices, &distances);
    // The nearest is the point itself (or an exact duplicate); take the first non-zero distance.
    for (double d : distances) {
      if (d > 0.0) {
        spacing.push_back(d);
        break;
      }
    }
  }
  if (spacing.empty()) return 0.0;
  return PercentileInPlace(&spacing, 0.5);
}

}  // namespace ibrdf
