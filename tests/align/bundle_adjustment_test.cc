// The bundle adjustment without a known layout: a synthetic target session whose markers' layout is
// withheld (one origin marker fixes the world frame) must give the markers' corners within 0.2 mm and
// the cameras within the bounds (0.5 mm, 0.05 degrees) once the truth is put in that frame;
// the mixed case (some markers known, the others estimated) needs no gauge transform at all.
#include "align/bundle_adjustment.h"

#include <cmath>
#include <functional>
#include <iostream>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "align/aligner.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/math.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

SynthOptions FreeLayoutOptions(int photos) {
  SynthOptions options;
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = photos;
  return options;
}

// The world frame an origin marker defines (session-format.md, targets.unknown_layout) from its true
// corners: centre, x to the right, y up the print, z out of it.
Rigid3d OriginFromWorld(const TargetSpec& origin) {
  const Eigen::Vector3d center = 0.25 * (origin.corners[0] + origin.corners[1] + origin.corners[2] + origin.corners[3]);
  const Eigen::Vector3d x = (origin.corners[1] - origin.corners[0]).normalized();
  const Eigen::Vector3d y = (origin.corners[0] - origin.corners[3]).normalized();
  Eigen::Matrix3d world_from_origin;
  world_from_origin << x, y, x.cross(y);
  const Rigid3d world_from_origin_pose(Eigen::Quaterniond(world_from_origin), center);
  return world_from_origin_pose.Inverse();
}

double PositionErrorM(const Rigid3d& estimated, const Rigid3d& expected) {
  return (estimated.Inverse().translation - expected.Inverse().translation).norm();
}
double RotationErrorDeg(const Rigid3d& estimated, const Rigid3d& expected) {
  return estimated.rotation.angularDistance(expected.rotation) / kDegree;
}

TEST(BundleAdjustment, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(BundleAdjustmentOptions().Check(&why)) << why;
}

// Without any fixed marker the gauge is free: a clear failure, not a drifting answer.
TEST(BundleAdjustment, NoFixedMarkerIsAFailure) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 800, 600, {1000, 1000, 400, 300}, "test");
  std::map<int, BundleMarker> markers;
  BundleMarker& marker = markers[3];
  marker.id = 3;
  marker.size = 0.03;
  marker.posed = true;
  marker.world_from_marker = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  marker.UpdateCorners();
  std::vector<BundleImage> images(1);
  images[0].posed = true;
  images[0].camera_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 0.5));
  for (int c = 0; c < 4; ++c) {
    images[0].corners.push_back({3, c, camera.ImageFromCamera(images[0].camera_from_world * marker.corners[c]), true});
  }
  const BundleAdjustmentSummary summary = BundleAdjust(camera, BundleAdjustmentOptions(), &images, &markers);
  EXPECT_FALSE(summary.success);
  EXPECT_NE(summary.message.find("gauge"), std::string::npos) << summary.message;
}

// The pose uncertainty grows as the corners shrink towards a line: a ring of markers is well
// conditioned, the same number of corners squeezed into a thin strip is not.
TEST(BundleAdjustment, UncertaintyGrowsForNearlyCollinearCorners) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 800, 600, {1200, 1200, 400, 300}, "test");
  const Rigid3d camera_from_world(Eigen::Quaterniond(Eigen::AngleAxisd(0.8 * M_PI, Eigen::Vector3d::UnitX())),
                                  Eigen::Vector3d(0.0, 0.0, 0.8));
  auto uncertainty = [&](double spread_y) {
    std::map<int, BundleMarker> markers;
    BundleImage image;
    image.posed = true;
    image.camera_from_world = camera_from_world;
    for (int k = 0; k < 6; ++k) {
      BundleMarker& marker = markers[k];
      marker.id = k;
      marker.fixed = marker.posed = true;
      const Eigen::Vector3d center(0.1 * std::cos(k * M_PI / 3), spread_y * std::sin(k * M_PI / 3), 0.0);
      for (int c = 0; c < 4; ++c) {
        // Tiny markers: nearly all the geometry comes from their layout.
        marker.corners[c] = center + Eigen::Vector3d(c == 1 || c == 2 ? 1e-3 : -1e-3, c >= 2 ? 1e-3 : -1e-3, 0.0);
        image.corners.push_back({k, c, camera.ImageFromCamera(camera_from_world * marker.corners[c]), true});
      }
    }
    return EstimatePoseUncertainty(camera, image, markers, 0.1);
  };
  const PoseUncertainty ring = uncertainty(0.1), strip = uncertainty(0.002);
  EXPECT_LT(ring.position_sigma_m, 0.5e-3);
  EXPECT_GT(strip.rotation_sigma_deg, 10.0 * ring.rotation_sigma_deg);
  EXPECT_GT(strip.position_sigma_m, 10.0 * ring.position_sigma_m);
}

// The free-layout case end to end on rendered photos: layout withheld, marker 0 the origin.
TEST(BundleAdjustment, UnknownLayoutFromRenderedPhotos) {
  ScratchDir dir;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session truth = Session::Load(MakeSession(dir / "s", FreeLayoutOptions(8), *material));
  const Rigid3d origin_from_world = OriginFromWorld(truth.targets->reference[0]);
  Session session = truth;
  UnknownLayoutSpec layout;
  layout.size = (truth.targets->reference[0].corners[1] - truth.targets->reference[0].corners[0]).norm();
  for (const TargetSpec& target : truth.targets->reference) layout.ids.push_back(target.id);
  layout.origin_id = 0;
  session.targets->reference.clear();
  session.targets->unknown_layout = layout;
  // The session's own guesses, stated in the origin marker's frame.
  session.sample.center = origin_from_world * truth.sample.center + Eigen::Vector3d(0.001, -0.001, 0.002);
  session.lights[0].position = origin_from_world * truth.lights[0].position;
  for (PhotoSpec& photo : session.photos) photo.camera_from_world.reset();

  const AlignResult result = AlignSession(session, AlignOptions());
  std::cout << result.bundle.BriefReport() << "\n" << result.BriefReport() << "\n";
  EXPECT_EQ(result.bundle.fixed_markers, 1);
  EXPECT_EQ(result.bundle.free_markers, static_cast<int>(layout.ids.size()) - 1);
  // Every marker's corners within 0.2 mm, in the origin marker's frame.
  double worst_corner = 0.0;
  for (const TargetSpec& expected : truth.targets->reference) {
    const TargetSpec* estimated = nullptr;
    for (const TargetSpec& t : result.session.targets->reference) {
      if (t.id == expected.id) estimated = &t;
    }
    ASSERT_NE(estimated, nullptr) << "marker " << expected.id << " not posed";
    for (int c = 0; c < 4; ++c) {
      const double error = (estimated->corners[c] - origin_from_world * expected.corners[c]).norm();
      worst_corner = std::max(worst_corner, error);
      EXPECT_LT(error, 0.2e-3) << "marker " << expected.id << " corner " << c;
    }
  }
  EXPECT_FALSE(result.session.targets->unknown_layout);  // all posed: all in the reference layout now
  // Cameras within the bounds, the truth in the origin frame.
  const Rigid3d world_from_origin = origin_from_world.Inverse();
  ASSERT_EQ(result.session.photos.size(), truth.photos.size());
  double worst_position = 0.0, worst_rotation = 0.0;
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    const Rigid3d expected = *truth.photos[i].camera_from_world * world_from_origin;
    const Rigid3d& estimated = *result.session.photos[i].camera_from_world;
    worst_position = std::max(worst_position, PositionErrorM(estimated, expected));
    worst_rotation = std::max(worst_rotation, RotationErrorDeg(estimated, expected));
    EXPECT_LT(PositionErrorM(estimated, expected), 0.5e-3) << "photo " << i;
    EXPECT_LT(RotationErrorDeg(estimated, expected), 0.05) << "photo " << i;
  }
  ASSERT_TRUE(result.sphere.fitted);
  const double centre_error = (result.sphere.center - origin_from_world * truth.sample.center).norm();
  EXPECT_LT(centre_error, 0.2e-3);
  EXPECT_NEAR(result.sphere.radius, truth.sample.radius, 0.1e-3);
  std::cout << "unknown layout: worst corner " << 1e3 * worst_corner << " mm, camera " << 1e3 * worst_position
            << " mm, " << worst_rotation << " deg, sphere centre " << 1e3 * centre_error << " mm, radius "
            << 1e3 * std::abs(result.sphere.radius - truth.sample.radius) << " mm\n";
}

// The unknown_layout block round-trips; a missing gauge, a gauge given twice and an origin not in
// the list are errors naming the field.
TEST(BundleAdjustment, UnknownLayoutInTheSessionFile) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = FreeLayoutOptions(1);
  options.rig.width = 160;
  options.rig.height = 120;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  nlohmann::json json = session.ToJson();
  json["targets"].erase("reference");
  json["targets"]["unknown_layout"] = {{"size", 0.028}, {"ids", {0, 1, 2}}, {"origin_id", 1}};
  WriteJsonFile(dir / "s/session.json", json);
  const Session reloaded = Session::Load(dir / "s");
  ASSERT_TRUE(reloaded.targets->unknown_layout);
  EXPECT_EQ(*reloaded.targets->unknown_layout->origin_id, 1);
  EXPECT_EQ(reloaded.ToJson()["targets"]["unknown_layout"], json["targets"]["unknown_layout"]);
  auto expect_error = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& where,
                          const std::string& what) {
    nlohmann::json broken = json;
    edit(broken);
    WriteJsonFile(dir / "s/session.json", broken);
    try {
      Session::Load(dir / "s");
      ADD_FAILURE() << "expected an error at " << where;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error([](nlohmann::json& j) { j["targets"]["unknown_layout"].erase("origin_id"); },
               "/targets/unknown_layout/origin_id", "give origin_id");
  expect_error([](nlohmann::json& j) { j["targets"]["unknown_layout"]["origin_id"] = 7; },
               "/targets/unknown_layout/origin_id", "not in ids");
  expect_error([&](nlohmann::json& j) { j["targets"]["reference"] = session.ToJson()["targets"]["reference"]; },
               "/targets/unknown_layout/ids/0", "listed twice");
  expect_error([](nlohmann::json& j) { j["targets"]["unknown_layout"]["size"] = -1; }, "/targets/unknown_layout/size",
               "");
}

// Mixed: half the ring known (fixed, the world frame), the other half estimated in that frame.
TEST(BundleAdjustment, MixedKnownAndUnknownLayout) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options = FreeLayoutOptions(5);
  const Session truth = Session::Load(MakeSession(dir / "s", options, material));
  Session session = truth;
  UnknownLayoutSpec layout;
  layout.size = options.targets.marker_size;
  session.targets->reference.clear();
  for (const TargetSpec& target : truth.targets->reference) {
    if (target.id % 2 == 0) {
      session.targets->reference.push_back(target);
    } else {
      layout.ids.push_back(target.id);
    }
  }
  session.targets->unknown_layout = layout;
  AlignOptions align_options;
  align_options.fit_sphere = false;
  const AlignResult result = AlignSession(session, align_options);
  EXPECT_EQ(result.bundle.free_markers, 6);
  for (const MarkerResidual& marker : result.markers) {
    if (marker.kind != "unknown") continue;
    for (int c = 0; c < 4; ++c) {
      EXPECT_LT((marker.corners[c] - truth.targets->reference[marker.id].corners[c]).norm(), 0.2e-3)
          << "marker " << marker.id << " corner " << c;
    }
  }
  for (const ImageAlignment& image : result.images) {
    if (!image.used) std::cout << "photo " << image.photo << " dropped: " << image.dropped_reason << "\n";
  }
  ASSERT_EQ(result.session.photos.size(), truth.photos.size());
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    EXPECT_LT(PositionErrorM(*result.session.photos[i].camera_from_world, *truth.photos[i].camera_from_world), 0.5e-3);
    EXPECT_LT(RotationErrorDeg(*result.session.photos[i].camera_from_world, *truth.photos[i].camera_from_world), 0.05);
  }
}

}  // namespace
}  // namespace ibrdf
