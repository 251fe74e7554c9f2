#include "spatial/material_clusters.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/error.h"
#include "core/logging.h"

namespace ibrdf {
namespace {

struct Partition {
  std::vector<Eigen::Vector3d> centres;
  std::vector<int> label;
  double sse = std::numeric_limits<double>::infinity();
};

// OpenCV's k-means (k-means++ seeds, `starts` attempts, the most compact kept), from a fixed seed so
// that the same cells give the same groups.
Partition KMeans(const cv::Mat& points, int k, int starts) {
  cv::theRNG().state = 1;
  cv::Mat labels, centres;
  Partition p;
  p.sse = cv::kmeans(points, k, labels, cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-9),
                     starts, cv::KMEANS_PP_CENTERS, centres);
  for (int c = 0; c < centres.rows; ++c) {
    p.centres.emplace_back(centres.at<float>(c, 0), centres.at<float>(c, 1), centres.at<float>(c, 2));
  }
  p.label.assign(labels.begin<int>(), labels.end<int>());
  return p;
}

}  // namespace

bool MaterialClusterOptions::Check(std::string* why) const {
  if (max_materials < 1 || max_materials > 16) {
    *why = "max materials must be 1 to 16";
    return false;
  }
  if (!(separation > 0.0) || !(blend_tolerance > 0.0)) {
    *why = "separation and blend tolerance must be positive";
    return false;
  }
  if (!(min_share >= 0.0 && min_share < 0.5)) {
    *why = "min share must be in [0, 0.5)";
    return false;
  }
  if (starts < 1) {
    *why = "starts must be positive";
    return false;
  }
  return true;
}

MaterialClusters ClusterMaterials(const std::vector<Eigen::Vector3d>& cell_ratio, const MaterialClusterOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("material cluster options", why);
  MaterialClusters result;
  result.cell_label.assign(cell_ratio.size(), -1);
  std::vector<Eigen::Vector3d> points;
  std::vector<size_t> cell_of_point;
  for (size_t c = 0; c < cell_ratio.size(); ++c) {
    const Eigen::Vector3d& r = cell_ratio[c];
    bool all = true;
    Eigen::Vector3d log_ratio;
    for (int k = 0; k < 3; ++k) {
      all &= std::isfinite(r[k]) && r[k] > 0.0;
      if (all) log_ratio[k] = std::log(r[k]);
    }
    if (!all) continue;
    points.push_back(log_ratio);
    cell_of_point.push_back(c);
  }
  result.clustered = points.size();
  if (points.empty()) return result;

  const double log_separation = std::log1p(options.separation), log_blend = std::log1p(options.blend_tolerance);
  // k = 1: every cell in one group about the mean.
  Partition taken;
  taken.centres = {Eigen::Vector3d::Zero()};
  for (const Eigen::Vector3d& p : points) taken.centres[0] += p / double(points.size());
  taken.label.assign(points.size(), 0);
  result.tried.push_back("1: always");
  cv::Mat data(int(points.size()), 3, CV_32F);
  for (size_t i = 0; i < points.size(); ++i) {
    for (int a = 0; a < 3; ++a) data.at<float>(int(i), a) = float(points[i][a]);
  }
  for (int k = 2; k <= options.max_materials && size_t(k) <= points.size(); ++k) {
    const Partition best = KMeans(data, k, options.starts);
    // The closest pair of centres (by their largest channel difference) and the smallest cluster.
    double closest = std::numeric_limits<double>::infinity();
    for (size_t a = 0; a < best.centres.size(); ++a) {
      for (size_t b = a + 1; b < best.centres.size(); ++b) {
        closest = std::min(closest, (best.centres[a] - best.centres[b]).cwiseAbs().maxCoeff());
      }
    }
    std::vector<size_t> counts(best.centres.size(), 0);
    for (int label : best.label) ++counts[label];
    const double smallest = double(*std::min_element(counts.begin(), counts.end())) / double(points.size());
    const bool apart = closest > log_separation, large = smallest >= options.min_share;
    result.tried.push_back(std::to_string(k) + ": closest centres " + Fixed(std::exp(closest), 2) + "x apart (" +
                           (apart ? "over " : "not over ") + Fixed(1.0 + options.separation, 2) + "x), smallest " +
                           Fixed(100.0 * smallest, 1) + " % of cells (" + (large ? "at least " : "under ") +
                           Fixed(100.0 * options.min_share, 0) + " %)");
    if (apart && large) taken = best;
  }

  result.count = int(taken.centres.size());
  result.share.assign(result.count, 0.0);
  for (size_t i = 0; i < points.size(); ++i) {
    result.cell_label[cell_of_point[i]] = taken.label[i];
    result.share[taken.label[i]] += 1.0 / double(points.size());
  }
  for (const Eigen::Vector3d& c : taken.centres) result.ratio.push_back(c.array().exp().matrix());

  // A group whose centre is, within the blend tolerance, a mix of two others' (the cells of a smooth
  // boundary between two materials) is their blend: the others are the materials.
  result.blend_of.assign(result.count, {-1, -1});
  for (int c = 0; c < result.count && result.count >= 3; ++c) {
    double best = std::numeric_limits<double>::infinity();
    for (int a = 0; a < result.count; ++a) {
      for (int b = a + 1; b < result.count; ++b) {
        if (a == c || b == c) continue;
        // The closest point of the segment between the two centres (linear ratios), by the largest
        // channel difference of the logarithms, over a fine sweep of the mix.
        for (int step = 1; step < 100; ++step) {
          const double t = step / 100.0;
          const Eigen::Vector3d mix = (1.0 - t) * result.ratio[a] + t * result.ratio[b];
          const double d = (mix.array().log() - taken.centres[c].array()).abs().maxCoeff();
          if (d < best) {
            best = d;
            if (d < log_blend) result.blend_of[c] = {a, b};
          }
        }
      }
    }
  }
  // Blends of blends are not materials either, but at least two materials remain.
  int blends = 0;
  for (const auto& pair : result.blend_of) blends += pair[0] >= 0;
  if (result.count - blends < 2) result.blend_of.assign(result.count, {-1, -1});
  result.materials = result.count;
  for (const auto& pair : result.blend_of) result.materials -= pair[0] >= 0;
  return result;
}

bool MaterialClusters::IsBlend(int group) const {
  return group >= 0 && size_t(group) < blend_of.size() && blend_of[group][0] >= 0;
}

std::string MaterialClusters::BriefReport() const {
  if (count == 0) return "cells not grouped: none scored in all three channels";
  if (count == 1) return "the cells form one group";
  std::string text = "the cells form " + std::to_string(count) + " groups (cells";
  for (int c = 0; c < count; ++c) text += (c ? " / " : " ") + Fixed(100.0 * share[c], 0);
  text += " %; off-peak values";
  for (int c = 0; c < count; ++c) {
    text += (c ? ", " : " ") + Fixed(ratio[c][0], 2) + " " + Fixed(ratio[c][1], 2) + " " + Fixed(ratio[c][2], 2);
  }
  text += " of the median cell's)";
  if (materials < count) {
    text += ": " + std::to_string(materials) + " materials";
    for (int c = 0; c < count; ++c) {
      if (IsBlend(c)) {
        text += ", group " + std::to_string(c) + " a blend of " + std::to_string(blend_of[c][0]) + " and " +
                std::to_string(blend_of[c][1]);
      }
    }
  }
  return text;
}

nlohmann::json MaterialClusters::ToJson() const {
  nlohmann::json clusters = nlohmann::json::array();
  for (int c = 0; c < count; ++c) {
    nlohmann::json entry = {{"share", share[c]}, {"ratio", {ratio[c][0], ratio[c][1], ratio[c][2]}}};
    if (IsBlend(c)) entry["blend_of"] = {blend_of[c][0], blend_of[c][1]};
    clusters.push_back(entry);
  }
  return {{"count", count},         {"materials", materials}, {"clustered_cells", clustered},
          {"clusters", clusters}, {"tried", tried}};
}

}  // namespace ibrdf
