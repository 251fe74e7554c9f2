// The silhouette sphere fit (align/sphere_fit.h) on real photos: the UW photometric-stereo grey sphere
// (../shared/data/uw-photometric-spheres/gray, 12 lights, one photo each, fixed near-orthographic
// camera, 8-bit TGA, black background). Each photo shows only its lit limb, so each photo's centre
// (with the radius known) moves with any bias of the lit limb's edge: inwards moves it away from that
// photo's light. The test fits all 12 photos together (free radius) against the hand-drawn mask's
// circle, then each photo alone with that radius, and measures the per-photo centres' spread and their
// mean displacement towards the light (docs/benchmarks.md, issue 13, "the lit limb's bias"). Skips
// with a message when the data folder is absent.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "align/mirror_sphere.h"
#include "align/sphere_fit.h"
#include "core/image_io.h"

namespace ibrdf {
namespace {

std::string DataDir() { return std::string(IBRDF_SHARED_DATA_DIR) + "/uw-photometric-spheres"; }

// The near-orthographic camera as a long-focal pinhole far away (as scripts/uw-spheres): the camera
// looks down -z of lights.txt's frame (x right, y up, z towards the viewer) from z = kDistance.
constexpr double kFocal = 1e6, kNominalRadius = 0.05;
constexpr double kDistance = kNominalRadius * kFocal / 120.0;

TEST(UwGreySphere, LitLimbsAgreeAcrossLights) {
  if (!std::filesystem::exists(DataDir() + "/gray/gray.mask.tga")) {
    GTEST_SKIP() << "no UW data at " << DataDir() << " (../shared/data/uw-photometric-spheres)";
  }
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 512, 340, {kFocal, kFocal, 256.0, 170.0});
  const Rigid3d camera_from_world(Eigen::Quaterniond(0.0, 1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 0.0, kDistance));
  const double metres_per_px = kDistance / kFocal;
  // The mask's circle: the start, and a coarse reference (the mask is drawn by hand).
  const PixelMask mask = ReadPixelMask(DataDir() + "/gray/gray.mask.tga", 512, 340);
  const SphereSilhouette circle = FitSphereSilhouette(camera, MaskEdgePoints(mask));
  ASSERT_TRUE(circle.fitted) << circle.reason;
  const Eigen::Vector3d start((circle.center_px.x() - 256.0) * metres_per_px,
                              -(circle.center_px.y() - 170.0) * metres_per_px,
                              kDistance - kNominalRadius * kFocal / circle.radius_px);

  std::vector<Image> images;
  for (int k = 0; k < 12; ++k) images.push_back(ReadImage(DataDir() + "/gray/gray." + std::to_string(k) + ".tga"));
  std::vector<Eigen::Vector3d> lights(12);
  {
    std::ifstream in(DataDir() + "/lights.txt");
    int count = 0;
    in >> count;
    ASSERT_EQ(count, 12);
    for (auto& l : lights) in >> l.x() >> l.y() >> l.z();
  }

  // All 12 photos together. One viewpoint: the cone of tangent rays fixes only the ratio of radius to
  // distance, so the radius stays nominal and the depth gives the apparent radius.
  std::vector<SilhouettePhoto> photos;
  for (const Image& image : images) photos.push_back({&image, camera_from_world});
  SphereFitOptions options;
  options.fix_radius = true;
  const SphereFit all = FitSphereToSilhouettes(camera, photos, start, kNominalRadius, options);
  ASSERT_TRUE(all.fitted) << all.reason;
  const Eigen::Vector3d all_camera = camera_from_world * all.center;
  const Eigen::Vector2d all_px = camera.ImageFromCamera(all_camera);
  const double all_radius_px = kFocal * all.radius / std::sqrt(all_camera.squaredNorm() - all.radius * all.radius);
  std::printf("mask circle: centre (%.3f, %.3f) px, radius %.3f px\n", circle.center_px.x(), circle.center_px.y(),
              circle.radius_px);
  std::printf("12 photos: centre (%.3f, %.3f) px, apparent radius %.3f px, %d points, RMS %.3f px\n", all_px.x(),
              all_px.y(), all_radius_px, all.silhouette_points, all.rms_m / metres_per_px);
  EXPECT_LT((all_px - circle.center_px).norm(), 1.5);
  EXPECT_NEAR(all_radius_px, circle.radius_px, 1.5);

  // Each photo alone: its limb points (SilhouettePoints, 3 px around the 12-photo silhouette), a
  // circle of the 12-photo radius fitted to them (Gauss-Newton on the centre, points beyond 3 x RMS
  // dropped once); the centre's displacement towards the photo's light in the image (lights.txt's y is
  // up, the image's down).
  std::vector<Eigen::Vector2d> centres;
  std::vector<double> towards;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int k = 0; k < 12; ++k) {
    std::vector<Eigen::Vector2d> points =
        SilhouettePoints(images[k], camera, camera_from_world, all.center, all.radius, options.silhouette_lines, 3.0);
    ASSERT_GE(points.size(), 20u) << "light " << k;
    Eigen::Vector2d c = all_px;
    for (int pass = 0; pass < 2; ++pass) {
      for (int iteration = 0; iteration < 20; ++iteration) {
        Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();
        Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
        for (const Eigen::Vector2d& p : points) {
          const Eigen::Vector2d u = (c - p).normalized();
          jtj += u * u.transpose();
          jtr += u * ((p - c).norm() - all_radius_px);
        }
        c -= jtj.ldlt().solve(jtr);
      }
      double squared = 0.0;
      for (const Eigen::Vector2d& p : points) squared += std::pow((p - c).norm() - all_radius_px, 2) / points.size();
      std::vector<Eigen::Vector2d> kept;
      for (const Eigen::Vector2d& p : points) {
        if (std::abs((p - c).norm() - all_radius_px) <= 3.0 * std::sqrt(squared)) kept.push_back(p);
      }
      points = kept;
    }
    centres.push_back(c);
    mean += c / 12.0;
  }
  double spread = 0.0, mean_towards = 0.0;
  for (int k = 0; k < 12; ++k) {
    const Eigen::Vector2d light_px = Eigen::Vector2d(lights[k].x(), -lights[k].y()).normalized();
    towards.push_back((centres[k] - all_px).dot(light_px));
    mean_towards += towards.back() / 12.0;
    spread += (centres[k] - mean).squaredNorm() / 12.0;
    std::printf("light %2d: centre (%.3f, %.3f) px, %+.3f px towards the light\n", k, centres[k].x(), centres[k].y(),
                towards.back());
  }
  spread = std::sqrt(spread);
  std::printf("per-photo centres (radius known): spread %.3f px RMS, mean displacement towards the light %+.3f px\n",
              spread, mean_towards);
  // Bounds from the measured figures (docs/benchmarks.md, issue 13: before the limb model, 0.29 px
  // away from the light and 0.39 px spread; after, see there).
  EXPECT_LT(std::abs(mean_towards), 0.2);
  EXPECT_LT(spread, 0.45);
}

}  // namespace
}  // namespace ibrdf
