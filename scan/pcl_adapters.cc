// PCL, in this one translation unit (it compiles slowly and pulls VTK).
#include <cmath>
#include <filesystem>
#include <type_traits>

#include <pcl/console/print.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "core/error.h"
#include "core/file_util.h"
#include "scan/adapters.h"

namespace ibrdf::scan_adapters {
namespace {
// PCL prints its own errors; the callers throw Errors instead.
class QuietPcl {
 public:
  QuietPcl() : level_(pcl::console::getVerbosityLevel()) { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }
  ~QuietPcl() { pcl::console::setVerbosityLevel(level_); }

 private:
  pcl::console::VERBOSITY_LEVEL level_;
};

pcl::PointCloud<pcl::PointXYZ>::Ptr CentredCloud(const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d centre = Centroid(points);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i] - centre;
    (*cloud)[i] = pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  return cloud;
}
}  // namespace

ScanMesh ReadPcdFile(const std::string& path) {
  RequireFile(path, "scan file");
  if (std::filesystem::file_size(path) == 0) ThrowError(path, "empty file");
  pcl::PCLPointCloud2 blob;
  {
    QuietPcl quiet;
    pcl::PCDReader reader;
    if (reader.read(path, blob) < 0) ThrowError(path, "PCL cannot read this PCD file (malformed or truncated)");
  }
  bool has_normals = false;
  for (const auto& field : blob.fields) has_normals |= field.name == "normal_x";
  ScanMesh mesh;
  // The same loop for both point types; normals only for the type that has them.
  auto append = [&](const auto& cloud) {
    for (const auto& p : cloud) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        if (cloud.isOrganized()) continue;
        ThrowError(path, "a point has a NaN or infinite coordinate");
      }
      mesh.points.emplace_back(p.x, p.y, p.z);
      if constexpr (std::is_same_v<std::decay_t<decltype(p)>, pcl::PointNormal>) {
        mesh.normals.emplace_back(p.normal_x, p.normal_y, p.normal_z);
      }
    }
  };
  if (has_normals) {
    pcl::PointCloud<pcl::PointNormal> cloud;
    pcl::fromPCLPointCloud2(blob, cloud);
    append(cloud);
  } else {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    pcl::fromPCLPointCloud2(blob, cloud);
    append(cloud);
  }
  for (const Eigen::Vector3d& n : mesh.normals) {
    if (!n.allFinite()) ThrowError(path, "a point has a NaN or infinite normal");
  }
  if (mesh.points.empty()) ThrowError(path, "no points");
  return mesh;
}

std::vector<bool> StatisticalInliers(const std::vector<Eigen::Vector3d>& points, int mean_k, double stddev_mul) {
  std::vector<bool> keep(points.size(), true);
  if (points.size() <= static_cast<size_t>(mean_k)) return keep;
  QuietPcl quiet;
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> filter;
  filter.setInputCloud(CentredCloud(points));
  filter.setMeanK(mean_k);
  filter.setStddevMulThresh(stddev_mul);
  pcl::Indices inliers;
  filter.filter(inliers);
  keep.assign(points.size(), false);
  for (const auto i : inliers) keep[i] = true;
  return keep;
}

std::vector<Eigen::Vector3d> PclNormals(const std::vector<Eigen::Vector3d>& points, double radius_m, int threads) {
  QuietPcl quiet;
  const auto cloud = CentredCloud(points);
  pcl::PointCloud<pcl::Normal> normals;
  if (threads <= 1) {
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    estimation.setInputCloud(cloud);
    estimation.setRadiusSearch(radius_m);
    estimation.compute(normals);
  } else {
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimation(threads);
    estimation.setInputCloud(cloud);
    estimation.setRadiusSearch(radius_m);
    estimation.compute(normals);
  }
  std::vector<Eigen::Vector3d> out(points.size(), Eigen::Vector3d::Zero());
  for (size_t i = 0; i < points.size() && i < normals.size(); ++i) {
    const Eigen::Vector3d n(normals[i].normal_x, normals[i].normal_y, normals[i].normal_z);
    if (n.allFinite() && n.norm() > 0.5) out[i] = n.normalized();
  }
  return out;
}

}  // namespace ibrdf::scan_adapters
