// Tests of calibrate/mirror_sphere.h: the silhouette cone fit, the highlight, the law of reflection and its
// uncertainty, triangulation; end to end on synthetic mirror-sphere photos (synth/synthetic_mirror_sphere.h).
#include "calibrate/mirror_sphere.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/math.h"
#include "synth/synthetic_mirror_sphere.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / kPi;
}

Camera TestCamera() { return Camera::Create(CameraModelId::kPinhole, 400, 300, {1500.0, 1500.0, 200.0, 150.0}); }

// A mask of the pixel centres whose rays meet a sphere (camera frame).
PixelMask SphereMask(const Camera& camera, const Eigen::Vector3d& center, double radius) {
  PixelMask mask;
  mask.width = camera.width;
  mask.height = camera.height;
  mask.usable.assign(size_t(mask.width) * mask.height, 0);
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const Eigen::Vector2d xy = camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
      const Eigen::Vector3d ray = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
      const double along = ray.dot(center);
      mask.usable[size_t(y) * mask.width + x] = (center - along * ray).squaredNorm() <= radius * radius ? 1 : 0;
    }
  }
  return mask;
}

TEST(MirrorSphere, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(SilhouetteFitOptions().Check(&why)) << why;
  EXPECT_TRUE(HighlightOptions().Check(&why)) << why;
  HighlightOptions bad;
  bad.core_fraction = 0.1;  // below the blob level
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("core_fraction"), std::string::npos) << why;
}

TEST(MirrorSphere, SilhouetteOfAnOffAxisSphere) {
  // Off the optical axis the silhouette is an ellipse; the cone fit recovers the centre's ray and the
  // half angle from a binary mask to a small fraction of a pixel.
  const Camera camera = TestCamera();
  const Eigen::Vector3d center(0.012, -0.008, 0.5);
  const double radius = 0.02;
  const SphereSilhouette truth = SphereSilhouette::FromCenter(camera, center, radius);
  const SphereSilhouette fit = FitSphereSilhouette(camera, MaskEdgePoints(SphereMask(camera, center, radius)));
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.center_px - truth.center_px).norm(), 0.05) << fit.BriefReport() << " vs " << truth.BriefReport();
  EXPECT_NEAR(fit.radius_px, truth.radius_px, 0.05);
  EXPECT_LT((fit.CenterInCamera(radius) - center).norm(), 0.0005);
  EXPECT_LT(fit.rms_px, 0.5);
  EXPECT_GT(fit.covariance(2, 2), 0.0);
}

TEST(MirrorSphere, SilhouetteWithTooFewPointsIsNotFitted) {
  const SphereSilhouette fit = FitSphereSilhouette(TestCamera(), {Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2)});
  EXPECT_FALSE(fit.fitted);
  EXPECT_NE(fit.reason.find("edge points"), std::string::npos) << fit.reason;
}

TEST(MirrorSphere, ReflectionRecoversTheLight) {
  // Forward: the normal bisecting the view ray and the light; its surface point's pixel; back.
  const Camera camera = TestCamera();
  const Eigen::Vector3d center(0.01, 0.005, 0.6);
  const double radius = 0.025;
  const SphereSilhouette sphere = SphereSilhouette::FromCenter(camera, center, radius);
  for (const Eigen::Vector3d& light : {Eigen::Vector3d(0.3, -0.4, -0.8), Eigen::Vector3d(-0.7, 0.1, -0.5)}) {
    const Eigen::Vector3d l = light.normalized();
    // Fixed point: the normal for a view ray from the camera to the point it gives.
    Eigen::Vector3d p = center - radius * Eigen::Vector3d::UnitZ();
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector3d v = -p.normalized();
      p = center + radius * (l + v).normalized();
    }
    Eigen::Vector3d direction, surface;
    ASSERT_TRUE(ReflectedDirection(camera, sphere, radius, camera.ImageFromCamera(p), &direction, &surface));
    EXPECT_LT(AngleDeg(direction, l), 1e-6);
    EXPECT_LT((surface - p).norm(), 1e-9);
  }
  Eigen::Vector3d direction, surface;
  EXPECT_FALSE(ReflectedDirection(camera, sphere, radius, Eigen::Vector2d(1, 1), &direction, &surface));
}

TEST(MirrorSphere, HighlightCentroidAndAmbiguity) {
  const Camera camera = TestCamera();
  const SphereSilhouette sphere = SphereSilhouette::FromCenter(camera, Eigen::Vector3d(0, 0, 0.5), 0.03);
  Image image(camera.width, camera.height, 3);
  const Eigen::Vector2d truth(213.37, 141.81);
  auto add_spot = [&](const Eigen::Vector2d& at, double peak) {
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const double r2 = (Eigen::Vector2d(x + 0.5, y + 0.5) - at).squaredNorm();
        for (int c = 0; c < 3; ++c) image.at(x, y, c) += float(std::min(1.0, peak * std::exp(-r2 / (2 * 1.5 * 1.5))));
      }
    }
  };
  add_spot(truth, 6.0);  // a clipped core, as a real highlight
  const Highlight h = LocateHighlight(image, sphere, nullptr);
  ASSERT_TRUE(h.found) << h.reason;
  EXPECT_LT((h.pixel - truth).norm(), 0.05) << h.BriefReport();
  EXPECT_GT(h.core_pixels, 1);
  EXPECT_GE(h.sigma_px, HighlightOptions().min_sigma_px);
  // A second, as bright, spot elsewhere on the sphere: which one is the light's is not decidable.
  add_spot(Eigen::Vector2d(180, 160), 6.0);
  const Highlight two = LocateHighlight(image, sphere, nullptr);
  EXPECT_FALSE(two.found);
  EXPECT_NE(two.reason.find("two bright spots"), std::string::npos) << two.reason;
  // Nothing bright at all.
  const Highlight none = LocateHighlight(Image(camera.width, camera.height, 3), sphere, nullptr);
  EXPECT_FALSE(none.found);
}

TEST(MirrorSphere, UncertaintyGrowsTowardsTheRim) {
  // Near the rim the normal changes faster per pixel: the same highlight error means a larger angle.
  const Camera camera = TestCamera();
  const SphereSilhouette sphere = SphereSilhouette::FromCenter(camera, Eigen::Vector3d(0, 0, 0.5), 0.03);
  Highlight centre, rim;
  centre.found = rim.found = true;
  centre.sigma_px = rim.sigma_px = 0.1;
  centre.pixel = sphere.center_px + Eigen::Vector2d(5, 0);
  rim.pixel = sphere.center_px + Eigen::Vector2d(0.9 * sphere.radius_px, 0);
  const MirrorDirection a = DirectionFromHighlight(camera, sphere, 0.03, centre);
  const MirrorDirection b = DirectionFromHighlight(camera, sphere, 0.03, rim);
  ASSERT_TRUE(a.valid && b.valid);
  // d(light)/d(pixel) = 2 / (radius_px cos(theta_n)) near the centre: 0.1 px -> ~0.13 deg (radius 90 px).
  const double expected = 2.0 * 0.1 / sphere.radius_px * 180.0 / kPi * std::sqrt(2.0);
  EXPECT_NEAR(a.sigma_deg, expected, 0.1 * expected);
  EXPECT_GT(b.sigma_deg, 1.5 * a.sigma_deg);  // radially 1 / cos(theta_n) = 2.3x, tangentially 1x
}

TEST(MirrorSphere, TriangulatesAPoint) {
  const Eigen::Vector3d light(0.3, 1.2, 0.9);
  const std::vector<Eigen::Vector3d> origins = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.2, 0, 0)};
  std::vector<Eigen::Vector3d> directions;
  for (const auto& o : origins) directions.push_back((light - o).normalized());
  Eigen::Vector3d point;
  Eigen::Matrix3d covariance;
  ASSERT_TRUE(TriangulateRays(origins, directions, {0.001, 0.001}, &point, &covariance));
  EXPECT_LT((point - light).norm(), 1e-9);
  EXPECT_GT(covariance.trace(), 0.0);
  // Parallel rays: no point.
  EXPECT_FALSE(TriangulateRays(origins, {directions[0], directions[0]}, {0.001, 0.001}, &point, &covariance));
}

TEST(MirrorSphere, SyntheticPhotosGiveTheTrueDirections) {
  // End to end on rendered 8-bit photos (an off-axis sphere, 12 lights): aim under 0.2 degrees.
  testing::ScratchDir scratch;
  SyntheticMirrorSphereOptions options;
  options.width = 480;
  options.height = 360;
  options.supersampling = 3;
  const SyntheticMirrorSphere truth = WriteSyntheticMirrorSphere(options, scratch / "m", false);
  const PixelMask mask = ReadPixelMask(scratch / "m/mask.png", options.width, options.height);
  const SphereSilhouette sphere = FitSphereSilhouette(truth.camera, MaskEdgePoints(mask));
  ASSERT_TRUE(sphere.fitted) << sphere.reason;
  const Eigen::Matrix3d world_from_camera = truth.camera_from_world.rotation.inverse().toRotationMatrix();
  double worst = 0.0;
  for (size_t k = 0; k < truth.lights.size(); ++k) {
    const Light& light = truth.lights[k];
    const std::string& id = truth.ids[k];
    const Image photo = ReadImage(scratch / ("m/photos/" + id + ".png"));
    const Highlight h = LocateHighlight(photo, sphere, &mask);
    ASSERT_TRUE(h.found) << id << ": " << h.reason;
    const MirrorDirection d = DirectionFromHighlight(truth.camera, sphere, options.radius, h);
    ASSERT_TRUE(d.valid) << d.reason;
    const double error = AngleDeg(world_from_camera * d.direction, light.direction);
    worst = std::max(worst, error);
    EXPECT_LT(error, 0.2) << id << " " << h.BriefReport();
    EXPECT_LT(error, 4.0 * d.sigma_deg + 0.02) << id << ": the uncertainty must cover the error";
    EXPECT_LT(d.sigma_deg, 0.2) << id;
  }
  EXPECT_LT(worst, 0.2);
  std::printf("synthetic mirror sphere: worst direction error %.4f deg over %zu lights\n", worst, truth.lights.size());
}

TEST(MirrorSphere, MaskOfTheWrongSizeIsAnError) {
  testing::ScratchDir scratch;
  WriteImage(scratch / "mask.png", Image(10, 10, 1), PixelFormat::kUint8);
  try {
    ReadPixelMask(scratch / "mask.png", 20, 10);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("mask.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("10 x 10"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ibrdf
