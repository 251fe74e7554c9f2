// The pbrt-v4 scene of a photo rendered from the measured model. The camera is checked against
// pbrt-v4's own definitions, restated here from its sources (mmp/pbrt-v4, src/pbrt/scene.cpp
// BasicSceneBuilder::ConcatTransform: ctm = ctm * Transpose(the 16 values), so they are column-major;
// src/pbrt/util/transform.cpp Perspective(fov, n, f): screen = (x, y) / (z tan(fov / 2));
// src/pbrt/cameras.h ProjectiveCamera: NDCFromScreen = Scale(1 / (max.x - min.x), 1 / (max.y - min.y), 1)
// * Translate(-min.x, -max.y, 0) and rasterFromNDC = Scale(xres, -yres, 1)): every world point must land
// on the pixel the session's camera projects it to (undistorted, for a camera with distortion). The
// pbrt-v4 binary of ../shared/oracles could not run on the machine this was written on (it exits with
// an illegal instruction), so no render is compared here.
#include "spatial/material_scene.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "scan/ply_io.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using testing::ScratchDir;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<double> Numbers(const std::string& text, const std::string& pattern) {
  std::smatch match;
  EXPECT_TRUE(std::regex_search(text, match, std::regex(pattern))) << pattern;
  std::vector<double> out;
  if (match.size() < 2) return out;
  std::istringstream in(match[1].str());
  for (double v; in >> v;) out.push_back(v);
  return out;
}

// A world point's raster position in pbrt-v4's camera as the scene defines it.
Eigen::Vector2d PbrtRaster(const std::string& scene, const Eigen::Vector3d& p_world) {
  EXPECT_NE(scene.find("Scale 1 -1 1\nConcatTransform ["), std::string::npos);
  const std::vector<double> m = Numbers(scene, R"(ConcatTransform \[([^\]]*)\])");
  const std::vector<double> window = Numbers(scene, R"(screenwindow" \[([^\]]*)\])");
  const std::vector<double> fov = Numbers(scene, R"("float fov" \[([^\]]*)\])");
  const std::vector<double> xres = Numbers(scene, R"(xresolution" \[([^\]]*)\])");
  const std::vector<double> yres = Numbers(scene, R"(yresolution" \[([^\]]*)\])");
  if (m.size() != 16 || window.size() != 4 || fov.size() != 1 || xres.size() != 1 || yres.size() != 1) return {};
  Eigen::Matrix4d camera_from_world;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) camera_from_world(row, col) = m[size_t(col * 4 + row)];
  }
  Eigen::Vector4d p = Eigen::Vector4d(1, -1, 1, 1).asDiagonal() * camera_from_world * p_world.homogeneous();
  const double t = std::tan(fov[0] * M_PI / 360.0);
  const double sx = p.x() / (p.z() * t), sy = p.y() / (p.z() * t);
  return {xres[0] * (sx - window[0]) / (window[1] - window[0]), -yres[0] * (sy - window[3]) / (window[3] - window[2])};
}

// A session of one photo of a 2 x 2-face square seen from 0.5 m, its point light above the camera.
Session SquareSession(const Camera& camera) {
  Session session;
  session.manifest_path = "test/session.json";
  session.camera = camera;
  PhotoSpec photo;
  photo.camera_from_world =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
              Eigen::Vector3d(0.01, -0.02, 0.5));
  session.photos = {photo, photo};
  session.photos[1].camera_from_world.reset();
  session.lights[0].position = Eigen::Vector3d(0.1, 0.2, 0.6);
  return session;
}

VertexMaterials Square() {
  VertexMaterials v;
  v.mesh.points = {{-0.05, -0.05, 0}, {0, -0.05, 0}, {0.05, -0.05, 0}, {-0.05, 0.05, 0}, {0, 0.05, 0}, {0.05, 0.05, 0}};
  v.mesh.faces = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}};
  v.bases = {0, 3};
  v.weights = Eigen::MatrixXd::Zero(6, 2);
  v.from.assign(6, VertexWeightsFrom::kOwnCell);
  // Left column pure group 0, middle 0.7 / 0.3, right column without weights.
  v.weights.row(0) << 1, 0;
  v.weights.row(3) << 1, 0;
  v.weights.row(1) << 0.4, 0.6;
  v.weights.row(4) << 0.4, 0.6;
  v.from[2] = v.from[5] = VertexWeightsFrom::kNone;
  v.label.assign(6, 0);
  v.fits.assign(6, 1);
  return v;
}

void ExpectCameraMatches(const Camera& camera) {
  ScratchDir dir;
  const Session session = SquareSession(camera);
  const PbrtSceneResult result = WritePbrtScene(session, 0, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"},
                                                {"a", "b"}, dir.str(), PbrtSceneOptions{});
  ASSERT_TRUE(result.written) << result.not_written;
  EXPECT_EQ(result.undistorted, camera.HasDistortion());
  const std::string scene = ReadText(dir / result.file);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p_world(u(rng), u(rng), u(rng));
    const Eigen::Vector3d p_camera = *session.photos[0].camera_from_world * p_world;
    const Eigen::Vector2d pixel = camera.ImageFromCamera(p_camera);
    // The undistorted pinhole's pixel of the same ray.
    const Eigen::Vector2d plane = camera.CamPlaneFromImage(pixel);
    const Eigen::Vector2d expected(camera.FocalX() * plane.x() + camera.PrincipalX(),
                                   camera.FocalY() * plane.y() + camera.PrincipalY());
    const Eigen::Vector2d raster = PbrtRaster(scene, p_world);
    EXPECT_NEAR((raster - expected).norm(), 0.0, 1e-6) << raster.transpose() << " vs " << expected.transpose();
  }
}

TEST(MaterialScene, PbrtsCameraSeesEachPointWhereThePhotoDoes) {
  ExpectCameraMatches(Camera::Create(CameraModelId::kPinhole, 800, 600, {1200.0, 1190.0, 410.5, 290.25}));
  ExpectCameraMatches(
      Camera::Create(CameraModelId::kOpenCV, 640, 480, {900.0, 900.0, 320.0, 240.0, -0.08, 0.02, 0.0005, -0.0003}));
}

TEST(MaterialScene, FacesTakeTheirVerticesMixAndUnweightedFacesAreBlack) {
  ScratchDir dir;
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 320, 240, {400.0, 400.0, 160.0, 120.0});
  const Session session = SquareSession(camera);
  PbrtSceneOptions options;
  const PbrtSceneResult result =
      WritePbrtScene(session, 0, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir.str(), options);
  ASSERT_TRUE(result.written);
  EXPECT_EQ(result.file, "pbrt/photo-0.pbrt");
  EXPECT_EQ(result.faces, 4u);
  EXPECT_EQ(result.faces_unmeasured, 2u);  // the right column: a vertex without weights
  const std::string scene = ReadText(dir / result.file);
  EXPECT_NE(scene.find("Include \"../group-0/a.pbrt\"\nInclude \"../group-3/b.pbrt\""), std::string::npos) << scene;
  // Face {0, 4, 3}: weights (1 + 0.4 + 1, 0.6) -> b's amount 0.6 / 3 = 0.2; face {0, 1, 4}: (1.8, 1.2) -> 0.4.
  EXPECT_NE(scene.find("\"float amount\" 0.4\n"), std::string::npos) << scene;
  EXPECT_NE(scene.find("MakeNamedMaterial \"mix-0-3-0.20\" \"string type\" \"mix\"\n"
                       "    \"string materials\" [ \"a\" \"b\" ] \"float amount\" 0.2"),
            std::string::npos)
      << scene;
  EXPECT_EQ(result.materials, 4);  // a, b and the two mixes
  EXPECT_NE(scene.find("NamedMaterial \"unmeasured\"\n  Shape \"plymesh\" \"string filename\" \"unmeasured.ply\""),
            std::string::npos);
  EXPECT_NE(scene.find("LightSource \"point\" \"point3 from\" [ 0.1 0.2 0.6 ]"), std::string::npos) << scene;
  EXPECT_EQ(ReadPly(dir / "pbrt/part-0.ply").faces.size(), 1u);
  EXPECT_EQ(ReadPly(dir / "pbrt/part-1.ply").faces.size(), 1u);
  EXPECT_EQ(ReadPly(dir / "pbrt/unmeasured.ply").faces.size(), 2u);
  EXPECT_EQ(ReadPly(dir / "pbrt/unmeasured.ply").points.size(), 4u);  // only the vertices its faces use

  const PbrtSceneResult no_pose =
      WritePbrtScene(session, 1, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir / "x", options);
  EXPECT_FALSE(no_pose.written);
  EXPECT_NE(no_pose.not_written.find("no pose"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
