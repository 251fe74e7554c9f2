// The silhouette sphere fit (align/sphere_fit.h) on real photos: the UW photometric-stereo grey sphere
// (../shared/data/uw-photometric-spheres/gray, 12 lights, one photo each, fixed near-orthographic
// camera, 8-bit TGA, a dark background and a stand below the sphere). Each photo shows mainly its lit
// limb, so each photo's centre (with the radius known) moves with any bias of the lit limb's edge:
// inwards moves it away from that photo's light. The test fits all 12 photos together against the
// hand-drawn mask's circle, then each photo alone with that radius, and compares the per-photo centres'
// spread and their mean displacement towards the light between the threshold edge and the limb model
// (docs/benchmarks.md, "Align: the sphere's lit limb"). Skips with a message when the data folder is
// absent.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "align/sphere_fit.h"
#include "calibrate/mirror_sphere.h"
#include "core/image_io.h"

namespace ibrdf {
namespace {

std::string DataDir() { return std::string(IBRDF_SHARED_DATA_DIR) + "/uw-photometric-spheres"; }

// The near-orthographic camera as a long-focal pinhole far away (as scripts/uw-spheres): the camera
// looks down -z of lights.txt's frame (x right, y up, z towards the viewer) from z = kDistance.
constexpr double kFocal = 1e6, kNominalRadius = 0.05;
constexpr double kDistance = kNominalRadius * kFocal / 120.0;

// What one edge model gives on the 12 photos: the 12-photo sphere's image, then each photo alone.
struct UwFigures {
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0, rms_px = 0.0;
  int points = 0;
  int photos = 0, lit_photos = 0;                    // photos in the per-photo figures
  double spread_px = 0.0, towards_px = 0.0;          // all of a photo's limb points
  double lit_spread_px = 0.0, lit_towards_px = 0.0;  // those within 60 degrees of its light's direction
};

// A circle of radius `radius` (pixels) fitted to `points` from `start`: Gauss-Newton on the centre,
// points beyond 3 x RMS dropped once and the fit repeated.
Eigen::Vector2d FitCircleCentre(std::vector<Eigen::Vector2d> points, const Eigen::Vector2d& start, double radius) {
  Eigen::Vector2d c = start;
  for (int pass = 0; pass < 2; ++pass) {
    for (int iteration = 0; iteration < 20; ++iteration) {
      Eigen::Matrix2d jtj = Eigen::Matrix2d::Zero();
      Eigen::Vector2d jtr = Eigen::Vector2d::Zero();
      for (const Eigen::Vector2d& p : points) {
        const Eigen::Vector2d u = (c - p).normalized();
        jtj += u * u.transpose();
        jtr += u * ((p - c).norm() - radius);
      }
      c -= jtj.ldlt().solve(jtr);
    }
    double squared = 0.0;
    for (const Eigen::Vector2d& p : points) squared += std::pow((p - c).norm() - radius, 2) / points.size();
    std::vector<Eigen::Vector2d> kept;
    for (const Eigen::Vector2d& p : points) {
      if (std::abs((p - c).norm() - radius) <= 3.0 * std::sqrt(squared)) kept.push_back(p);
    }
    points = kept;
  }
  return c;
}

// All 12 photos together, then each alone. One viewpoint: the cone of tangent rays fixes only the ratio
// of radius to distance, so the radius stays nominal and the depth gives the apparent radius. Each
// photo's limb points (SilhouettePoints, 3 px around the 12-photo silhouette) get a circle of the
// 12-photo radius; its centre's displacement towards the photo's light in the image (lights.txt's y is
// up, the image's down) and the centres' spread (RMS about their mean).
UwFigures Measure(const Camera& camera, const Rigid3d& camera_from_world, const std::vector<Image>& images,
                  const std::vector<Eigen::Vector3d>& lights, const Eigen::Vector3d& start,
                  const LimbEdgeOptions& edge) {
  UwFigures figures;
  std::vector<SilhouettePhoto> photos;
  for (const Image& image : images) photos.push_back({&image, camera_from_world});
  SphereFitOptions options;
  options.fix_radius = true;
  options.limb_edge = edge;
  const SphereFit all = FitSphereToSilhouettes(camera, photos, start, kNominalRadius, options);
  EXPECT_TRUE(all.fitted) << all.reason;
  const Eigen::Vector3d all_camera = camera_from_world * all.center;
  figures.center_px = camera.ImageFromCamera(all_camera);
  figures.radius_px = kFocal * all.radius / std::sqrt(all_camera.squaredNorm() - all.radius * all.radius);
  figures.points = all.silhouette_points;
  figures.rms_px = all.rms_m * kFocal / kDistance;
  for (int lit_only = 0; lit_only < 2; ++lit_only) {
    std::vector<Eigen::Vector2d> centres;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double towards = 0.0;
    for (size_t k = 0; k < images.size(); ++k) {
      const Eigen::Vector2d light_px = Eigen::Vector2d(lights[k].x(), -lights[k].y()).normalized();
      std::vector<Eigen::Vector2d> points;
      for (const Eigen::Vector2d& p : SilhouettePoints(images[k], camera, camera_from_world, all.center, all.radius,
                                                       options.silhouette_lines, 3.0, edge)) {
        if (!lit_only || (p - figures.center_px).normalized().dot(light_px) > 0.5) points.push_back(p);
      }
      // Every photo shows 20 limb points; a light near the camera's axis leaves few within 60 degrees of
      // its direction in the image (that photo is left out of the lit-limb figures).
      if (!lit_only) {
        EXPECT_GE(points.size(), 20u) << "light " << k;
      }
      if (points.size() < 20u) continue;
      centres.push_back(FitCircleCentre(points, figures.center_px, figures.radius_px));
      mean += centres.back();
      towards += (centres.back() - figures.center_px).dot(light_px);
    }
    EXPECT_GE(centres.size(), 6u);
    if (centres.empty()) continue;
    (lit_only ? figures.lit_photos : figures.photos) = static_cast<int>(centres.size());
    mean /= centres.size();
    double spread = 0.0;
    for (const Eigen::Vector2d& c : centres) spread += (c - mean).squaredNorm() / centres.size();
    (lit_only ? figures.lit_spread_px : figures.spread_px) = std::sqrt(spread);
    (lit_only ? figures.lit_towards_px : figures.towards_px) = towards / centres.size();
  }
  return figures;
}

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

  // The threshold edge alone (the fit before the limb model) and the limb model, on the same photos.
  LimbEdgeOptions threshold;
  threshold.enabled = false;
  const UwFigures before = Measure(camera, camera_from_world, images, lights, start, threshold);
  const UwFigures after = Measure(camera, camera_from_world, images, lights, start, LimbEdgeOptions());
  std::printf("mask circle: centre (%.3f, %.3f) px, radius %.3f px\n", circle.center_px.x(), circle.center_px.y(),
              circle.radius_px);
  for (const UwFigures* f : {&before, &after}) {
    std::printf(
        "%s: 12 photos: centre (%.3f, %.3f) px, apparent radius %.3f px, %d points, RMS %.3f px; per photo "
        "(radius known): all points (%d photos): spread %.3f px, towards the light %+.3f px; lit limb only (%d "
        "photos): spread %.3f px, towards the light %+.3f px\n",
        f == &before ? "threshold edge" : "limb model", f->center_px.x(), f->center_px.y(), f->radius_px, f->points,
        f->rms_px, f->photos, f->spread_px, f->towards_px, f->lit_photos, f->lit_spread_px, f->lit_towards_px);
  }
  EXPECT_LT((after.center_px - circle.center_px).norm(), 1.5);
  EXPECT_NEAR(after.radius_px, circle.radius_px, 1.5);
  // The limb model is no worse than the threshold edge on real photos (measured: docs/benchmarks.md,
  // "Align: the sphere's lit limb"): on the lit limb its per-photo centres agree better and do not
  // move towards or away from their lights.
  EXPECT_LE(after.rms_px, before.rms_px);
  EXPECT_LE(after.lit_spread_px, before.lit_spread_px);
  EXPECT_LE(std::abs(after.lit_towards_px), std::abs(before.lit_towards_px));
  EXPECT_LE(after.spread_px, before.spread_px);
  EXPECT_LE(std::abs(after.towards_px), std::abs(before.towards_px));
}

}  // namespace
}  // namespace ibrdf
