#include "align/markers.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/camera.h"
#include "core/error.h"

namespace ibrdf {
namespace {

struct NamedDictionary {
  const char* name;
  int id;
  int bits;
  int size;
};

constexpr NamedDictionary kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50, 4, 50},    {"DICT_4X4_100", cv::aruco::DICT_4X4_100, 4, 100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250, 4, 250}, {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000, 4, 1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50, 5, 50},    {"DICT_5X5_100", cv::aruco::DICT_5X5_100, 5, 100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250, 5, 250}, {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000, 5, 1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50, 6, 50},    {"DICT_6X6_100", cv::aruco::DICT_6X6_100, 6, 100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250, 6, 250}, {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000, 6, 1000},
};

}  // namespace

void RefineMarkerCorners(const Image& image, const Camera& camera, std::vector<MarkerDetection>* detections) {
  // Two passes: the second measures the edges from the first pass's corners.
  for (int pass = 0; pass < 2; ++pass)
    for (MarkerDetection& d : *detections) {
      // Side k runs from corner k to corner k + 1; the marker's inside is to the side's right in image
      // coordinates (y down), since corners go clockwise on screen.
      std::array<Eigen::Vector3d, 4> lines;  // a x + b y + c = 0 in the undistorted image plane
      bool ok = true;
      for (int k = 0; k < 4 && ok; ++k) {
        const Eigen::Vector2d a = d.corners[k], b = d.corners[(k + 1) % 4];
        const double length = (b - a).norm();
        const Eigen::Vector2d along = (b - a) / length;
        const Eigen::Vector2d inward(-along.y(), along.x());
        std::vector<Eigen::Vector2d> edge_points;
        const int samples = std::max(6, static_cast<int>(length));
        for (int j = 0; j < samples; ++j) {
          const double t = 0.15 + 0.7 * (j + 0.5) / samples;  // stay clear of the corners
          const Eigen::Vector2d base = a + t * (b - a);
          // Profile across the edge, from 3 px outside (white card) to 3 px inside (black border).
          const double step = 0.1, reach = 3.0;
          std::vector<double> profile;
          for (double s = -reach; s <= reach + 1e-9; s += step) {
            const Eigen::Vector2d p = base + s * inward;
            profile.push_back(BilinearLuminance(image, p.x(), p.y()));
          }
          if (std::any_of(profile.begin(), profile.end(), [](double v) { return !std::isfinite(v); })) continue;
          const double outside = profile.front(), inside = profile.back();
          if (!(outside > inside + 0.05)) continue;  // no clear white-to-black step
          // The edge by area: the white fraction of the profile, integrated, is the distance from the
          // outer end to the edge. Exact for a box-filtered step (what a sensor records), where a
          // mid-level crossing of interpolated samples is biased by up to a tenth of a pixel.
          double area = 0.0;
          for (size_t i = 0; i + 1 < profile.size(); ++i) {
            const double f0 = (profile[i] - inside) / (outside - inside),
                         f1 = (profile[i + 1] - inside) / (outside - inside);
            area += 0.5 * (f0 + f1) * step;
          }
          const double best = area - reach;
          if (std::abs(best) > 2.0) continue;  // the detected edge was further off than the refinement reaches
          if (!std::isfinite(best)) continue;
          edge_points.push_back(camera.CamPlaneFromImage(base + best * inward));
        }
        if (edge_points.size() < 4) {
          ok = false;
          break;
        }
        // Total least squares line through the edge points.
        Eigen::Vector2d mean = Eigen::Vector2d::Zero();
        for (const auto& p : edge_points) mean += p;
        mean /= edge_points.size();
        Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
        for (const auto& p : edge_points) scatter += (p - mean) * (p - mean).transpose();
        // The normal is the eigenvector of the smaller eigenvalue (Eigen's solver: the closed form is
        // ill-conditioned for sides along an image axis).
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
        Eigen::Vector2d normal = eigen.eigenvectors().col(0);
        if (eigen.info() != Eigen::Success || !(normal.norm() > 0.0)) {
          ok = false;
          break;
        }
        normal.normalize();
        lines[k] = Eigen::Vector3d(normal.x(), normal.y(), -normal.dot(mean));
      }
      if (!ok) continue;
      for (int k = 0; k < 4; ++k) {
        // Corner k lies on side k - 1 and side k.
        const Eigen::Vector3d corner = lines[(k + 3) % 4].cross(lines[k]);
        if (!(std::abs(corner.z()) > 1e-12)) continue;
        const Eigen::Vector2d xy = corner.head<2>() / corner.z();
        const Eigen::Vector2d d_xy = camera.Distort(xy);
        const Eigen::Vector2d pixel(camera.FocalX() * d_xy.x() + camera.PrincipalX(),
                                    camera.FocalY() * d_xy.y() + camera.PrincipalY());
        if ((pixel - d.corners[k]).norm() < 2.0) d.corners[k] = pixel;  // a large jump means a bad fit
      }
    }
}

MarkerDictionary::MarkerDictionary(const std::string& name, const std::string& where) : name_(name) {
  for (const NamedDictionary& d : kDictionaries) {
    if (name == d.name) {
      id_ = d.id;
      bits_ = d.bits;
      size_ = d.size;
      return;
    }
  }
  ThrowError(where,
             "unknown ArUco dictionary \"" + name + "\" (expected e.g. DICT_4X4_50, DICT_5X5_100, DICT_6X6_250)");
}

std::vector<bool> MarkerDictionary::Modules(int id) const {
  IBRDF_CHECK(id >= 0 && id < size_) << "marker id " << id << " outside " << name_;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(id_);
  cv::Mat image;
  cv::aruco::drawMarker(dictionary, id, modules(), image, 1);
  std::vector<bool> cells(size_t(modules()) * modules());
  for (int r = 0; r < modules(); ++r) {
    for (int c = 0; c < modules(); ++c) cells[size_t(r) * modules() + c] = image.at<uint8_t>(r, c) > 127;
  }
  return cells;
}

std::vector<MarkerDetection> DetectMarkers(const Image& image, const MarkerDictionary& dictionary,
                                           const MarkerDetectionOptions& options) {
  cv::Mat grey(image.height, image.width, CV_8UC1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      double v = 0.0;
      if (image.channels >= 3) {
        v = 0.2126 * image.at(x, y, 0) + 0.7152 * image.at(x, y, 1) + 0.0722 * image.at(x, y, 2);
      } else {
        v = image.at(x, y, 0);
      }
      if (!std::isfinite(v)) v = 0.0;
      grey.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(255.0 * std::pow(std::clamp(v, 0.0, 1.0), 1.0 / 2.2)));
    }
  }
  cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  if (options.subpixel) {
    parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    parameters->cornerRefinementWinSize = 3;
    parameters->cornerRefinementMaxIterations = 100;
    parameters->cornerRefinementMinAccuracy = 0.001;
  }
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(
      grey, cv::aruco::getPredefinedDictionary(cv::aruco::PREDEFINED_DICTIONARY_NAME(dictionary.id_for_opencv())),
      corners, ids, parameters);
  std::vector<MarkerDetection> detections;
  for (size_t i = 0; i < ids.size(); ++i) {
    MarkerDetection detection;
    detection.id = ids[i];
    double shortest = 1e30;
    for (int k = 0; k < 4; ++k) {
      // OpenCV puts pixel centres at integers; ibrdf (COLMAP) at +0.5.
      detection.corners[k] = Eigen::Vector2d(corners[i][k].x + 0.5, corners[i][k].y + 0.5);
    }
    for (int k = 0; k < 4; ++k)
      shortest = std::min(shortest, (detection.corners[k] - detection.corners[(k + 1) % 4]).norm());
    if (shortest >= options.min_side_px) detections.push_back(detection);
  }
  return detections;
}

}  // namespace ibrdf
