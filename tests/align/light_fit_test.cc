// The light fit (align/light_fit.h) on small exact inputs: light markers of known pose seen by posed
// photos give the light's position exactly; the joint refinement restores photo poses that start off;
// a light no photo sees is not fitted, with the reason; bad options are an error.
#include "align/light_fit.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/math.h"

namespace ibrdf {
namespace {

Rigid3d Pose(const Eigen::Vector3d& axis_angle_deg, const Eigen::Vector3d& translation) {
  const double angle = axis_angle_deg.norm() * kDegree;
  const Eigen::Quaterniond rotation = angle > 0.0
                                          ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis_angle_deg.normalized()))
                                          : Eigen::Quaterniond::Identity();
  return Rigid3d(rotation, translation);
}

// Two light markers 8 cm wide facing three cameras about a metre away (world +z into the prints), a
// point light behind them, and eight layout corners (two heights) that hold the photos' poses.
struct Scene {
  Camera camera = Camera::Create(CameraModelId::kPinhole, 800, 600, {800, 800, 400, 300});
  Eigen::Vector3d light = Eigen::Vector3d(0.05, -0.02, 0.3);
  LightTargetsSpec spec;
  std::vector<Rigid3d> world_from_marker = {Pose({0, 8, 2}, {-0.15, 0.02, 0.0}),
                                            Pose({-5, -6, 0}, {0.14, -0.03, 0.01})};
  std::vector<Rigid3d> camera_from_world = {Pose({2, -4, 0}, {0.1, 0.0, 1.0}), Pose({-3, 5, 1}, {-0.1, 0.05, 1.1}),
                                            Pose({0, 2, -3}, {0.0, -0.1, 0.9})};
  std::vector<Eigen::Vector3d> layout;

  Scene() {
    spec.size = 0.08;
    for (size_t m = 0; m < world_from_marker.size(); ++m) {
      LightMarkerSpec marker;
      marker.id = 10 + static_cast<int>(m);
      marker.light_in_marker = world_from_marker[m].Inverse() * light;
      spec.markers.push_back(marker);
    }
    for (int k = 0; k < 8; ++k)
      layout.emplace_back(-0.2 + 0.4 * (k % 4) / 3.0, k < 4 ? -0.15 : 0.15, k % 2 == 0 ? 0.0 : 0.05);
  }

  // The exact pixels of marker m's corners in photo i (OpenCV's order: x right, y down the print).
  std::array<Eigen::Vector2d, 4> Corners(size_t m, size_t i) const {
    const double h = 0.5 * spec.size;
    const Eigen::Vector3d in_marker[4] = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    std::array<Eigen::Vector2d, 4> pixels;
    for (int c = 0; c < 4; ++c)
      pixels[c] = camera.ImageFromCamera(camera_from_world[i] * (world_from_marker[m] * in_marker[c]));
    return pixels;
  }

  // Every photo, posed at `poses`, seeing every light marker and every layout corner.
  std::vector<LightFitPhoto> Photos(const std::vector<Rigid3d>& poses) const {
    std::vector<LightFitPhoto> photos;
    for (size_t i = 0; i < poses.size(); ++i) {
      LightFitPhoto photo;
      photo.photo = 2 * i;  // photo indices need not be contiguous
      photo.camera_from_world = poses[i];
      for (size_t m = 0; m < world_from_marker.size(); ++m) photo.light_markers[spec.markers[m].id] = Corners(m, i);
      for (const Eigen::Vector3d& p : layout)
        photo.layout_corners.push_back({camera.ImageFromCamera(camera_from_world[i] * p), p});
      photos.push_back(photo);
    }
    return photos;
  }
};

TEST(LightFit, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(LightFitOptions().Check(&why)) << why;
  LightFitOptions bad;
  bad.huber_px = 0.0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_EQ(why, "huber_px > 0.0 failed: huber_px = 0");
}

// Exact corners from exact poses: the light where it is, every marker agreeing, the poses unchanged.
TEST(LightFit, KnownLightFromExactMarkerPoses) {
  const Scene scene;
  const LightFit fit =
      FitLightToMarkers(scene.camera, scene.spec, scene.Photos(scene.camera_from_world), LightFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_TRUE(fit.reason.empty());
  EXPECT_LT((fit.position - scene.light).norm(), 1e-9);
  EXPECT_LT(fit.spread_m, 1e-9);
  ASSERT_EQ(fit.markers.size(), 2u);
  for (size_t m = 0; m < fit.markers.size(); ++m) {
    EXPECT_EQ(fit.markers[m].id, scene.spec.markers[m].id);
    EXPECT_EQ(fit.markers[m].photos, 3);
    EXPECT_LT(fit.markers[m].rms_px, 1e-6);
    EXPECT_LT((fit.markers[m].world_from_marker.translation - scene.world_from_marker[m].translation).norm(), 1e-9);
    EXPECT_LT(fit.markers[m].world_from_marker.rotation.angularDistance(scene.world_from_marker[m].rotation), 1e-9);
  }
  ASSERT_EQ(fit.refined_camera_from_world.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const Rigid3d& refined = fit.refined_camera_from_world.at(2 * i);
    EXPECT_LT((refined.translation - scene.camera_from_world[i].translation).norm(), 1e-9) << "photo " << i;
  }
  EXPECT_NE(fit.BriefReport().find("light at (0.05000, -0.02000, 0.30000) m from 2 markers"), std::string::npos)
      << fit.BriefReport();
}

// Photos whose poses start 2 mm and 0.1 degrees off: the layout corners and the light markers pull
// them back, and the light comes out right.
TEST(LightFit, RefinementRestoresPosesThatStartOff) {
  const Scene scene;
  std::vector<Rigid3d> start = scene.camera_from_world;
  for (Rigid3d& pose : start) pose = Pose({0.1, 0, 0}, {0.002, -0.001, 0.001}) * pose;
  const LightFit fit = FitLightToMarkers(scene.camera, scene.spec, scene.Photos(start), LightFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_LT((fit.position - scene.light).norm(), 1e-7);
  for (size_t i = 0; i < 3; ++i) {
    const Rigid3d& refined = fit.refined_camera_from_world.at(2 * i);
    EXPECT_LT((refined.translation - scene.camera_from_world[i].translation).norm(), 1e-7) << "photo " << i;
    EXPECT_LT(refined.rotation.angularDistance(scene.camera_from_world[i].rotation), 1e-8) << "photo " << i;
  }
}

// A marker no photo sees has no estimate; the light comes from the other.
TEST(LightFit, UnseenMarkerHasNoEstimate) {
  const Scene scene;
  std::vector<LightFitPhoto> photos = scene.Photos(scene.camera_from_world);
  for (LightFitPhoto& photo : photos) photo.light_markers.erase(scene.spec.markers[1].id);
  const LightFit fit = FitLightToMarkers(scene.camera, scene.spec, photos, LightFitOptions());
  ASSERT_TRUE(fit.fitted) << fit.reason;
  EXPECT_EQ(fit.markers[0].photos, 3);
  EXPECT_EQ(fit.markers[1].photos, 0);
  EXPECT_LT((fit.position - scene.light).norm(), 1e-9);
  EXPECT_EQ(fit.spread_m, 0.0);
}

// Degenerate: no photo sees a light marker (or there are no photos): not fitted, the reason says so,
// and no pose is touched.
TEST(LightFit, NoMarkerSeenIsNotFitted) {
  const Scene scene;
  std::vector<LightFitPhoto> photos = scene.Photos(scene.camera_from_world);
  for (LightFitPhoto& photo : photos) photo.light_markers.clear();
  for (const std::vector<LightFitPhoto>& input : {photos, std::vector<LightFitPhoto>()}) {
    const LightFit fit = FitLightToMarkers(scene.camera, scene.spec, input, LightFitOptions());
    EXPECT_FALSE(fit.fitted);
    EXPECT_NE(fit.reason.find("no marker of the light was seen"), std::string::npos) << fit.reason;
    EXPECT_TRUE(fit.refined_camera_from_world.empty());
    ASSERT_EQ(fit.markers.size(), 2u);
    for (const LightMarkerFit& marker : fit.markers) EXPECT_EQ(marker.photos, 0);
    EXPECT_EQ(fit.BriefReport(), fit.reason + "; the light stays as given");
  }
}

TEST(LightFit, BadOptionsAreAnError) {
  const Scene scene;
  LightFitOptions bad;
  bad.tolerance = -1.0;
  EXPECT_THROW(FitLightToMarkers(scene.camera, scene.spec, scene.Photos(scene.camera_from_world), bad), Error);
}

}  // namespace
}  // namespace ibrdf
