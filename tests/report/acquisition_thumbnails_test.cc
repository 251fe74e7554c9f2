// report/acquisition_thumbnails.h: the sample's outline projected into each photo (sphere limb,
// cylinder rims and limb lines, mesh silhouette edges) and drawn over the photo's thumbnail.
#include "report/acquisition_thumbnails.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/math.h"
#include "radiometry/linear_image.h"
#include "scan/ply_io.h"
#include "scan/scan_mesh.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

Session MakeSynthetic(const ScratchDir& dir, SampleSpec::Kind kind, bool distortion, int photos = 3) {
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.scene.sample = kind;
  options.rig.num_photos = photos;
  options.rig.width = 320;
  options.rig.height = 240;
  if (!distortion) options.rig.k1 = options.rig.k2 = options.rig.p1 = options.rig.p2 = 0.0;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  return Session::Load(MakeSession(dir / "s", options, material));
}

// The unit ray (world frame) from the camera centre through `pixel`, via the camera model's inverse
// (core/camera.h CamPlaneFromImage), independent of the projection SampleOutline uses.
Eigen::Vector3d Ray(const Session& session, const Rigid3d& camera_from_world, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d plane = session.camera.CamPlaneFromImage(pixel);
  return (camera_from_world.rotation.inverse() * Eigen::Vector3d(plane.x(), plane.y(), 1.0)).normalized();
}

// A closed UV sphere of `radius` about the origin (3-degree rings and segments), faces counter-clockwise
// seen from outside.
ScanMesh UvSphere(double radius) {
  ScanMesh mesh;
  const int rings = 60, segments = 120;
  mesh.points.push_back(Eigen::Vector3d(0, 0, radius));
  for (int i = 1; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const double t = kPi * i / rings, p = 2.0 * kPi * j / segments;
      mesh.points.push_back(radius *
                            Eigen::Vector3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)));
    }
  }
  mesh.points.push_back(Eigen::Vector3d(0, 0, -radius));
  const int south = int(mesh.points.size()) - 1;
  auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.faces.push_back(Eigen::Vector3i(0, at(1, j), at(1, j + 1)));
    mesh.faces.push_back(Eigen::Vector3i(south, at(rings - 1, j + 1), at(rings - 1, j)));
    for (int i = 1; i + 1 < rings; ++i) {
      mesh.faces.push_back(Eigen::Vector3i(at(i, j), at(i + 1, j), at(i + 1, j + 1)));
      mesh.faces.push_back(Eigen::Vector3i(at(i, j), at(i + 1, j + 1), at(i, j + 1)));
    }
  }
  return mesh;
}

TEST(AcquisitionThumbnails, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(AcquisitionThumbnailOptions().Check(&why)) << why;
  AcquisitionThumbnailOptions bad;
  bad.size_px = 4;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(why.find("size_px"), std::string::npos) << why;
}

// Every point of the sphere's outline, seen through the distorted camera, is a ray tangent to the
// sphere: its angle to the centre's direction is asin(R / d).
TEST(AcquisitionThumbnails, SphereOutlineRaysAreTangentThroughTheDistortion) {
  ScratchDir dir;
  const Session session = MakeSynthetic(dir, SampleSpec::Kind::kSphere, /*distortion=*/true);
  ASSERT_TRUE(session.camera.HasDistortion());
  for (const PhotoSpec& photo : session.photos) {
    ASSERT_TRUE(photo.camera_from_world);
    const Rigid3d& pose = *photo.camera_from_world;
    const Eigen::Vector3d eye = pose.Inverse().translation;
    const Eigen::Vector3d to_centre = session.sample.center - eye;
    const double tangent = std::asin(session.sample.radius / to_centre.norm());
    const auto outline = SampleOutline(session, pose, nullptr, 90);
    ASSERT_EQ(outline.size(), 1u);
    ASSERT_EQ(outline[0].size(), 91u);
    for (const Eigen::Vector2d& pixel : outline[0]) {
      const double angle = std::acos(std::clamp(Ray(session, pose, pixel).dot(to_centre.normalized()), -1.0, 1.0));
      EXPECT_NEAR(angle, tangent, 1e-7);
    }
  }
}

// The cylinder's limb lines are rays tangent to its side (at distance R from the axis) and its rims
// are the end circles: every outline point is a ray passing within R of the axis, and some at exactly R.
TEST(AcquisitionThumbnails, CylinderOutlineIsRimsAndTangentLimbLines) {
  ScratchDir dir;
  const Session session = MakeSynthetic(dir, SampleSpec::Kind::kCylinder, /*distortion=*/true, 2);
  ASSERT_EQ(session.sample.kind, SampleSpec::Kind::kCylinder);
  const Rigid3d& pose = *session.photos[0].camera_from_world;
  const auto outline = SampleOutline(session, pose, nullptr, 64);
  ASSERT_EQ(outline.size(), 4u);  // two rims, two limb lines
  const Eigen::Vector3d eye = pose.Inverse().translation, a = session.sample.axis.normalized();
  for (size_t k = 0; k < outline.size(); ++k) {
    for (const Eigen::Vector2d& pixel : outline[k]) {
      // The distance between the ray and the axis line.
      const Eigen::Vector3d ray = Ray(session, pose, pixel), n = ray.cross(a);
      const double distance = std::abs((eye - session.sample.center).dot(n.normalized()));
      if (k >= 2) {
        EXPECT_NEAR(distance, session.sample.radius, 1e-7);
      } else {
        EXPECT_LE(distance, session.sample.radius + 1e-7);
      }
    }
  }
}

// A tessellated sphere's silhouette edges lie on the analytic limb within the tessellation's sag.
TEST(AcquisitionThumbnails, MeshSilhouetteEdgesFollowTheLimb) {
  ScratchDir dir;
  Session session = MakeSynthetic(dir, SampleSpec::Kind::kSphere, /*distortion=*/true, 1);
  const Rigid3d& pose = *session.photos[0].camera_from_world;
  const Eigen::Vector3d eye = pose.Inverse().translation, centre = session.sample.center;
  const double r = session.sample.radius;
  // A UV sphere of radius r in a mesh frame scaled by 2 and shifted (world_from_mesh maps it back).
  const ScanMesh mesh = UvSphere(r / 2);
  session.sample.kind = SampleSpec::Kind::kMesh;
  session.sample.world_from_mesh = Sim3d(Eigen::Quaterniond::Identity(), centre, 2.0);
  const auto outline = SampleOutline(session, pose, &mesh);
  ASSERT_GT(outline.size(), 100u);
  const double tangent = std::asin(r / (centre - eye).norm());
  // A silhouette vertex lies up to a facet (3 to 4 degrees) off the limb, which brings its ray in by
  // about r (1 - cos 4 deg) ~ 2.4e-3 r: the angle is off by at most about that / d.
  for (const auto& line : outline) {
    for (const Eigen::Vector2d& pixel : line) {
      const double angle = std::acos(Ray(session, pose, pixel).dot((centre - eye).normalized()));
      EXPECT_NEAR(angle, tangent, 3e-3 * r / (centre - eye).norm());
    }
  }
}

// The written thumbnails: one per measurement photo; the green outline's pixels lie at the projected
// radius from the projected centre (undistorted camera: the limb projects to a circle when the camera
// looks at the centre), and the photo's own sphere edge is there: dark just outside, and lit just
// inside on the light's side.
TEST(AcquisitionThumbnails, ThumbnailOutlineLiesOnThePhotosSphereEdge) {
  ScratchDir dir;
  const Session session = MakeSynthetic(dir, SampleSpec::Kind::kSphere, /*distortion=*/false, 3);
  const nlohmann::json data = WriteAcquisitionThumbnails(session, {}, dir / "out");
  EXPECT_EQ(data.at("measurement_photos"), 3);
  EXPECT_EQ(data.at("shown"), 3);
  ASSERT_EQ(data.at("photos").size(), 3u);
  int lit_photos = 0;
  for (const nlohmann::json& entry : data.at("photos")) {
    ASSERT_FALSE(entry.contains("note")) << entry.dump();
    const size_t index = entry.at("index");
    EXPECT_TRUE(entry.at("outline").get<bool>());
    const Image thumbnail = ReadImage((fs::path(dir / "out") / entry.at("file").get<std::string>()).string());
    EXPECT_LE(std::max(thumbnail.width, thumbnail.height), 200);
    const int step = entry.at("step");
    const Eigen::Vector2d crop(entry.at("crop")[0].get<int>(), entry.at("crop")[1].get<int>());
    const Rigid3d& pose = *session.photos[index].camera_from_world;
    const Eigen::Vector3d c = pose * session.sample.center;
    const Eigen::Vector2d centre = session.camera.ImageFromCamera(c);
    const double d = c.norm(), r = session.sample.radius;
    // Looking at the centre: the limb's image is a circle of radius f tan(asin(r / d)).
    ASSERT_LT((centre - Eigen::Vector2d(session.camera.PrincipalX(), session.camera.PrincipalY())).norm(), 1e-6);
    const double radius = session.camera.FocalX() * r / std::sqrt(d * d - r * r);
    int green = 0;
    for (int y = 0; y < thumbnail.height; ++y) {
      for (int x = 0; x < thumbnail.width; ++x) {
        if (!(thumbnail.at(x, y, 0) == 0.0f && thumbnail.at(x, y, 1) == 1.0f && thumbnail.at(x, y, 2) == 0.0f))
          continue;
        ++green;
        const Eigen::Vector2d q = (Eigen::Vector2d(x + 0.5, y + 0.5) - (centre - crop) / step);
        EXPECT_NEAR(q.norm(), radius / step, 1.0) << "photo " << index << " pixel " << x << ", " << y;
      }
    }
    EXPECT_GT(green, 2.0 * kPi * radius / step) << "photo " << index;  // a closed curve, no gap
    // The photo: outside the limb (2 px) nothing, inside it (2 px) lit on at least a quarter of it.
    Image photo = ReadImage(session.PhotoPath(index));
    LinearizeImage(session, index, &photo, true);
    int lit = 0, points = 0;
    for (int k = 0; k < 360; ++k) {
      const Eigen::Vector2d u(std::cos(k * kDegree), std::sin(k * kDegree));
      const Eigen::Vector2d outside = centre + (radius + 2.0) * u, inside = centre + (radius - 2.0) * u;
      double value_out = 0.0, value_in = 0.0;
      for (int ch = 0; ch < 3; ++ch) {
        value_out += photo.at(int(outside.x()), int(outside.y()), std::min(ch, photo.channels - 1));
        value_in += photo.at(int(inside.x()), int(inside.y()), std::min(ch, photo.channels - 1));
      }
      EXPECT_LT(value_out, 1e-6) << "photo " << index << " at " << k << " deg";
      lit += value_in > 1e-4;
      ++points;
    }
    lit_photos += lit > points / 4;
  }
  // The arc's last photo looks against the light (its visible half unlit); the others see the lit side.
  EXPECT_GE(lit_photos, 2);
}

// More measurement photos than max_photos: an even subset with the first and the last.
TEST(AcquisitionThumbnails, ManyPhotosGiveAnEvenSubset) {
  ScratchDir dir;
  const Session session = MakeSynthetic(dir, SampleSpec::Kind::kSphere, true, 7);
  AcquisitionThumbnailOptions options;
  options.max_photos = 3;
  options.size_px = 64;
  const nlohmann::json data = WriteAcquisitionThumbnails(session, {}, dir / "out", options);
  EXPECT_EQ(data.at("measurement_photos"), 7);
  ASSERT_EQ(data.at("shown"), 3);
  EXPECT_EQ(data.at("photos")[0].at("index"), 0);
  EXPECT_EQ(data.at("photos")[1].at("index"), 3);
  EXPECT_EQ(data.at("photos")[2].at("index"), 6);
  const Image small = ReadImage((fs::path(dir / "out") / data.at("photos")[1].at("file").get<std::string>()).string());
  EXPECT_LE(std::max(small.width, small.height), 64);
}

// A mesh session: the mesh file (PLY, in the session's folder) is read and its silhouette drawn on
// the sphere's edge; a photo without a pose gets no outline; a missing mesh file is a note, the photos
// still shown.
TEST(AcquisitionThumbnails, MeshSessionReadsItsPlyAndPhotosWithoutPoseHaveNoOutline) {
  ScratchDir dir;
  Session session = MakeSynthetic(dir, SampleSpec::Kind::kSphere, /*distortion=*/true, 2);
  WritePly(dir / "s/mesh.ply", UvSphere(session.sample.radius));
  session.sample.kind = SampleSpec::Kind::kMesh;
  session.sample.mesh_file = "mesh.ply";
  session.sample.world_from_mesh = Sim3d(Eigen::Quaterniond::Identity(), session.sample.center, 1.0);
  session.photos[1].camera_from_world.reset();
  const nlohmann::json data = WriteAcquisitionThumbnails(session, {}, dir / "out");
  ASSERT_FALSE(data.contains("note")) << data.dump();
  ASSERT_EQ(data.at("photos").size(), 2u);
  EXPECT_TRUE(data.at("photos")[0].at("outline").get<bool>());
  EXPECT_FALSE(data.at("photos")[1].at("outline").get<bool>());
  const Image drawn = ReadImage((fs::path(dir / "out") / data.at("photos")[0].at("file").get<std::string>()).string());
  const Image plain = ReadImage((fs::path(dir / "out") / data.at("photos")[1].at("file").get<std::string>()).string());
  auto green = [](const Image& image) {
    int n = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        n += image.at(x, y, 0) == 0.0f && image.at(x, y, 1) == 1.0f && image.at(x, y, 2) == 0.0f;
      }
    }
    return n;
  };
  EXPECT_GT(green(drawn), 100);
  EXPECT_EQ(green(plain), 0);

  session.sample.mesh_file = "missing.ply";
  const nlohmann::json missing = WriteAcquisitionThumbnails(session, {}, dir / "out2");
  ASSERT_TRUE(missing.contains("note"));
  EXPECT_NE(missing.at("note").get<std::string>().find("missing.ply"), std::string::npos) << missing.dump();
  EXPECT_EQ(missing.at("shown"), 2);
  EXPECT_FALSE(missing.at("photos")[0].at("outline").get<bool>());
}

}  // namespace
}  // namespace ibrdf
