// The sphere fit (align/sphere_fit.h) on small exact inputs: exact tangent rays (and the rays through
// exact silhouette pixels) give the sphere exactly, outliers are rejected in the last round, small
// rendered images of a bright sphere on black give it to a fraction of a millimetre; too few
// silhouette points leave the sphere as given, with the reason; bad options are an error; the limb
// model places the edge of a limb that darkens towards its contour where the threshold edge cannot.
#include "align/sphere_fit.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

const Eigen::Vector3d kCenter(0.01, -0.02, 0.03);
constexpr double kRadius = 0.05;

// A camera at `position` looking at `target` (camera z forward, y down).
Rigid3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_camera;
  world_from_camera << x, y, z;
  return Rigid3d(Eigen::Quaterniond(world_from_camera), position).Inverse();
}

std::vector<Rigid3d> Cameras() {
  return {LookAt({0.5, 0.0, 0.1}, kCenter), LookAt({0.0, 0.45, 0.2}, kCenter), LookAt({-0.35, -0.3, 0.3}, kCenter)};
}

// `count` rays from `origin` tangent to the sphere, around its silhouette.
std::vector<TangentRay> TangentRays(const Eigen::Vector3d& origin, int count) {
  const Eigen::Vector3d w = (kCenter - origin).normalized();
  const double alpha = std::asin(kRadius / (kCenter - origin).norm());
  const Eigen::Vector3d u = w.unitOrthogonal(), v = w.cross(u);
  std::vector<TangentRay> rays;
  for (int k = 0; k < count; ++k) {
    const double phi = 2.0 * M_PI * k / count;
    rays.push_back(
        {origin, (std::cos(alpha) * w + std::sin(alpha) * (std::cos(phi) * u + std::sin(phi) * v)).normalized()});
  }
  return rays;
}

TEST(SphereFit, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(SphereFitOptions().Check(&why)) << why;
  SphereFitOptions bad;
  bad.silhouette_lines = 4;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "silhouette_lines >= 8 failed: silhouette_lines = 4");
}

// Exact tangent rays from three cameras: the sphere from a start 3 mm and 3 % off.
TEST(SphereFit, KnownSphereFromExactTangentRays) {
  std::vector<TangentRay> rays;
  for (const Rigid3d& pose : Cameras()) {
    for (const TangentRay& ray : TangentRays(pose.Inverse().translation, 24)) rays.push_back(ray);
  }
  const SphereFit fit = FitSphereToTangentRays(rays, kCenter + Eigen::Vector3d(0.002, -0.002, 0.001), 1.03 * kRadius,
                                               false, SphereFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.center - kCenter).norm(), 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
  EXPECT_EQ(fit.silhouette_points, 72);
  EXPECT_EQ(fit.rejected_points, 0);
  EXPECT_LT(fit.rms_m, 1e-10);
}

// Exact silhouette pixels (the projected tangent points): the rays through them give the sphere.
TEST(SphereFit, KnownSphereFromExactSilhouettePoints) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 320, 240, {300, 300, 160, 120});
  std::vector<TangentRay> rays;
  for (const Rigid3d& pose : Cameras()) {
    const Eigen::Vector3d origin = pose.Inverse().translation;
    const double along = std::sqrt((kCenter - origin).squaredNorm() - kRadius * kRadius);
    for (const TangentRay& tangent : TangentRays(origin, 16)) {
      const Eigen::Vector2d pixel = camera.ImageFromCamera(pose * (origin + along * tangent.direction));
      const TangentRay ray = RayThroughPixel(camera, pose, pixel);
      EXPECT_LT((ray.origin - origin).norm(), 1e-12);
      EXPECT_LT((ray.direction - tangent.direction).norm(), 1e-12);
      rays.push_back(ray);
    }
  }
  const SphereFit fit = FitSphereToTangentRays(rays, kCenter + Eigen::Vector3d(-0.003, 0.0, 0.002), 0.98 * kRadius,
                                               false, SphereFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.center - kCenter).norm(), 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
}

// Rays 5 mm off (edges of something else) in the last round: left out, and the sphere exact again.
TEST(SphereFit, LastRoundRejectsOutliers) {
  std::vector<TangentRay> rays;
  for (const Rigid3d& pose : Cameras()) {
    for (const TangentRay& ray : TangentRays(pose.Inverse().translation, 24)) rays.push_back(ray);
  }
  for (int k = 0; k < 4; ++k) {
    // Moved 5 mm away from the centre, perpendicular to itself.
    TangentRay outlier = rays[7 * k];
    const Eigen::Vector3d closest =
        outlier.origin + (kCenter - outlier.origin).dot(outlier.direction) * outlier.direction;
    outlier.origin += 0.005 * (closest - kCenter).normalized();
    rays.push_back(outlier);
  }
  const SphereFit fit = FitSphereToTangentRays(rays, kCenter, kRadius, true, SphereFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_EQ(fit.rejected_points, 4);
  EXPECT_EQ(fit.silhouette_points, 72);
  EXPECT_LT((fit.center - kCenter).norm(), 1e-9);
  EXPECT_NEAR(fit.radius, kRadius, 1e-9);
}

// A bright sphere on black, 4 x 4 samples per pixel (anti-aliased limb), luminance 0.5.
Image RenderSphere(const Camera& camera, const Rigid3d& camera_from_world) {
  Image image(camera.width, camera.height, 1);
  const Eigen::Vector3d center = camera_from_world * kCenter;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      int inside = 0;
      for (int sy = 0; sy < 4; ++sy) {
        for (int sx = 0; sx < 4; ++sx) {
          const Eigen::Vector2d xy = camera.CamPlaneFromImage(Eigen::Vector2d(x + (sx + 0.5) / 4, y + (sy + 0.5) / 4));
          const Eigen::Vector3d d = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
          inside += (center - center.dot(d) * d).norm() < kRadius;
        }
      }
      image.at(x, y, 0) = 0.5f * inside / 16.0f;
    }
  }
  return image;
}

// The whole fit on three small rendered photos, from a start 3 mm and 3 % off.
TEST(SphereFit, KnownSphereFromRenderedSilhouettes) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 200, 160, {300, 300, 100, 80});
  const std::vector<Rigid3d> poses = Cameras();
  std::vector<Image> images;
  for (const Rigid3d& pose : poses) images.push_back(RenderSphere(camera, pose));
  std::vector<SilhouettePhoto> photos;
  for (size_t i = 0; i < poses.size(); ++i) photos.push_back({&images[i], poses[i]});
  const int lines = SphereFitOptions().silhouette_lines;
  EXPECT_GT(SilhouettePoints(images[0], camera, poses[0], kCenter, kRadius, lines, 2.0).size(), size_t(0.9 * lines));
  const SphereFit fit = FitSphereToSilhouettes(camera, photos, kCenter + Eigen::Vector3d(0.002, 0.002, -0.001),
                                               1.03 * kRadius, SphereFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.center - kCenter).norm(), 0.2e-3) << fit.BriefReport();
  EXPECT_NEAR(fit.radius, kRadius, 0.1e-3) << fit.BriefReport();
  EXPECT_GT(fit.silhouette_points, 2 * lines);
}

// A disk image of a lit limb whose level falls like the square root of the depth inside the contour
// (a sphere's shading near its contour): `level` + `slope` sqrt(d) inside, 0.02 outside, each pixel the
// mean of 8 x 8 points (a sensor's pixel), then a Gaussian blur of `blur` pixels (0: none).
Image RenderLimbDisk(const Eigen::Vector2d& centre, double radius, double level, double slope, double blur) {
  Image image(400, 400, 1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      double sum = 0.0;
      for (int sy = 0; sy < 8; ++sy) {
        for (int sx = 0; sx < 8; ++sx) {
          const double d = radius - (Eigen::Vector2d(x + (sx + 0.5) / 8, y + (sy + 0.5) / 8) - centre).norm();
          sum += d > 0.0 ? level + slope * std::sqrt(d) : 0.02;
        }
      }
      image.at(x, y, 0) = static_cast<float>(sum / 64.0);
    }
  }
  if (blur <= 0.0) return image;
  Image blurred = image;
  for (int y = 5; y + 5 < image.height; ++y) {
    for (int x = 5; x + 5 < image.width; ++x) {
      double sum = 0.0, weights = 0.0;
      for (int dy = -4; dy <= 4; ++dy) {
        for (int dx = -4; dx <= 4; ++dx) {
          const double w = std::exp(-0.5 * (dx * dx + dy * dy) / (blur * blur));
          sum += w * image.at(x + dx, y + dy, 0);
          weights += w;
        }
      }
      blurred.at(x, y, 0) = static_cast<float>(sum / weights);
    }
  }
  return blurred;
}

// The lit limb's edge: where the level falls steeply towards the contour, the threshold edge sits
// inside it (by 0.3 px and more); the limb model puts it on the contour, sharp or blurred.
TEST(SphereFit, LimbModelFindsTheContourOfADarkeningLimb) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 400, 400, {1000, 1000, 200.3, 200.7});
  const double distance = 1.0, radius = 0.055;
  const double radius_px = 1000.0 * radius / std::sqrt(distance * distance - radius * radius);
  const Eigen::Vector2d centre(200.3, 200.7);
  const Rigid3d identity(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  LimbEdgeOptions threshold;
  threshold.enabled = false;
  for (const double blur : {0.0, 0.7, 1.2}) {
    const Image image = RenderLimbDisk(centre, radius_px, 0.05, 0.4, blur);
    for (const bool model : {false, true}) {
      const std::vector<Eigen::Vector2d> points =
          SilhouettePoints(image, camera, identity, Eigen::Vector3d(0.0, 0.0, distance), radius, 360, 1.5,
                           model ? LimbEdgeOptions() : threshold);
      ASSERT_GT(points.size(), 200u) << "blur " << blur << (model ? ", limb model" : ", threshold");
      double inside = 0.0;
      for (const Eigen::Vector2d& p : points) inside += (radius_px - (p - centre).norm()) / points.size();
      std::printf("blur %.1f px, %s: %zu points, mean %.4f px inside the contour\n", blur,
                  model ? "limb model" : "threshold", points.size(), inside);
      if (model) {
        EXPECT_LT(std::abs(inside), blur > 0.0 ? 0.03 : 0.1) << "blur " << blur;
      } else {
        EXPECT_GT(inside, 0.3) << "blur " << blur;  // the bias the model removes
      }
    }
  }
}

// Degenerate: fewer rays than a sphere needs, or photos without a silhouette (all black): not
// fitted, the start returned, the reason given.
TEST(SphereFit, TooFewPointsIsNotFitted) {
  const std::vector<TangentRay> rays = TangentRays(Eigen::Vector3d(0.5, 0.0, 0.1), 5);
  const SphereFit few = FitSphereToTangentRays(rays, kCenter, kRadius, false, SphereFitOptions());
  EXPECT_FALSE(few.fitted);
  EXPECT_NE(few.reason.find("only 5 silhouette points"), std::string::npos) << few.reason;
  EXPECT_EQ(few.center, kCenter);

  const Camera camera = Camera::Create(CameraModelId::kPinhole, 200, 160, {300, 300, 100, 80});
  const Image black(camera.width, camera.height, 1);
  const std::vector<SilhouettePhoto> photos = {{&black, Cameras()[0]}};
  const SphereFit none = FitSphereToSilhouettes(camera, photos, kCenter, kRadius, SphereFitOptions());
  EXPECT_FALSE(none.fitted);
  EXPECT_NE(none.reason.find("only 0 silhouette points"), std::string::npos) << none.reason;
  EXPECT_NE(none.BriefReport().find("sphere as given"), std::string::npos);
  const SphereFit empty = FitSphereToSilhouettes(camera, {}, kCenter, kRadius, SphereFitOptions());
  EXPECT_FALSE(empty.fitted);
}

TEST(SphereFit, BadOptionsAreAnError) {
  SphereFitOptions bad;
  bad.min_points = 2;
  EXPECT_THROW(FitSphereToSilhouettes(Camera::Create(CameraModelId::kPinhole, 200, 160, {300, 300, 100, 80}), {},
                                      kCenter, kRadius, bad),
               Error);
}

}  // namespace
}  // namespace ibrdf
