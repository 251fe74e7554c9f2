// The pbrt-v4 scene of a photo rendered from the measured model. The camera is checked against
// pbrt-v4's own definitions, restated here from its sources (mmp/pbrt-v4, src/pbrt/scene.cpp
// BasicSceneBuilder::ConcatTransform: ctm = ctm * Transpose(the 16 values), so they are column-major;
// src/pbrt/util/transform.cpp Perspective(fov, n, f): screen = (x, y) / (z tan(fov / 2));
// src/pbrt/cameras.h ProjectiveCamera: NDCFromScreen = Scale(1 / (max.x - min.x), 1 / (max.y - min.y), 1)
// * Translate(-min.x, -max.y, 0) and rasterFromNDC = Scale(xres, -yres, 1)): every world point must land
// on the pixel the session's camera projects it to (undistorted, for a camera with distortion).
// tests/spatial/material_scene_pbrt_test.cc renders a scene with pbrt-v4 itself. The Mitsuba 3 scene's
// camera is checked the same way against Mitsuba 3's definitions (mitsuba-renderer/mitsuba3,
// src/sensors/perspective.cpp: `to_world` takes camera to world, sample_direction's
// uv = camera_to_sample * p - principal_point_offset, times the film's size; include/mitsuba/render/
// sensor.h perspective_projection: camera_to_sample = Scale(-0.5, -0.5 aspect, 1) * Translate(-1,
// -1 / aspect, 0) * Perspective(x_fov), Perspective's screen (x, y) / (z tan(x_fov / 2)); <matrix> values
// are row-major); no Mitsuba 3 binary is at hand to render it.
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

// A world point's pixel position in Mitsuba 3's perspective camera as the scene defines it.
Eigen::Vector2d MitsubaRaster(const std::string& xml, const Eigen::Vector3d& p_world) {
  EXPECT_NE(xml.find("<string name=\"fov_axis\" value=\"x\"/>"), std::string::npos);
  const std::vector<double> fov = Numbers(xml, R"re(name="fov" value="([^"]*)")re");
  const std::vector<double> ox = Numbers(xml, R"re(name="principal_point_offset_x" value="([^"]*)")re");
  const std::vector<double> oy = Numbers(xml, R"re(name="principal_point_offset_y" value="([^"]*)")re");
  const std::vector<double> m = Numbers(xml, R"re(<matrix value="([^"]*)")re");
  const std::vector<double> width = Numbers(xml, R"re(name="width" value="([^"]*)")re");
  const std::vector<double> height = Numbers(xml, R"re(name="height" value="([^"]*)")re");
  if (fov.size() != 1 || ox.size() != 1 || oy.size() != 1 || m.size() != 16 || width.size() != 1 ||
      height.size() != 1) {
    return {};
  }
  Eigen::Matrix4d to_world;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) to_world(row, col) = m[size_t(row * 4 + col)];
  }
  // No scale allowed (perspective.cpp's constructor): a rotation.
  EXPECT_NEAR(
      (to_world.topLeftCorner<3, 3>() * to_world.topLeftCorner<3, 3>().transpose() - Eigen::Matrix3d::Identity())
          .norm(),
      0.0, 1e-9);
  const Eigen::Vector4d p = to_world.inverse() * p_world.homogeneous();
  const double t = std::tan(fov[0] * M_PI / 360.0), aspect = width[0] / height[0];
  const double sx = p.x() / (p.z() * t), sy = p.y() / (p.z() * t);
  const Eigen::Vector2d sample(-0.5 * (sx - 1.0), -0.5 * aspect * (sy - 1.0 / aspect));
  return {width[0] * (sample.x() - ox[0]), height[0] * (sample.y() - oy[0])};
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

// The groups' exported materials: a Mitsuba 3 snippet beside each pbrt-v4 one.
void WriteSnippets(const std::string& root) {
  for (const std::string name : {"a", "b"}) {
    const std::string folder = root + (name == std::string("a") ? "/group-0" : "/group-3");
    std::filesystem::create_directories(folder);
    std::ofstream(folder + "/" + name + ".pbrt")
        << "MakeNamedMaterial \"" << name << "\" \"string type\" \"diffuse\"\n";
    std::ofstream(folder + "/" + name + ".xml") << "<bsdf type=\"diffuse\" id=\"" << name << "\"/>\n";
  }
}

void ExpectCameraMatches(const Camera& camera) {
  ScratchDir dir;
  const Session session = SquareSession(camera);
  WriteSnippets(dir.str());
  const PbrtSceneResult result = WritePbrtScene(session, 0, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"},
                                                {"a", "b"}, dir.str(), PbrtSceneOptions{});
  ASSERT_TRUE(result.written) << result.not_written;
  EXPECT_EQ(result.undistorted, camera.HasDistortion());
  const std::string scene = ReadText(dir / result.file);
  ASSERT_EQ(result.mitsuba_file, "mitsuba/photo-0.xml") << result.mitsuba_not_written;
  const std::string xml = ReadText(dir / result.mitsuba_file);
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
    if (camera.FocalX() == camera.FocalY()) {
      const Eigen::Vector2d mitsuba = MitsubaRaster(xml, p_world);
      EXPECT_NEAR((mitsuba - expected).norm(), 0.0, 1e-6) << mitsuba.transpose() << " vs " << expected.transpose();
    }
  }
  EXPECT_EQ(xml.find("are not square") != std::string::npos, camera.FocalX() != camera.FocalY()) << xml;
}

TEST(MaterialScene, PbrtsCameraSeesEachPointWhereThePhotoDoes) {
  ExpectCameraMatches(Camera::Create(CameraModelId::kPinhole, 800, 600, {1200.0, 1190.0, 410.5, 290.25}));
  ExpectCameraMatches(Camera::Create(CameraModelId::kPinhole, 800, 600, {1100.0, 1100.0, 380.25, 310.5}));
  ExpectCameraMatches(
      Camera::Create(CameraModelId::kOpenCV, 640, 480, {900.0, 900.0, 320.0, 240.0, -0.08, 0.02, 0.0005, -0.0003}));
}

TEST(MaterialScene, FacesTakeTheirVerticesMixAndUnweightedFacesAreBlack) {
  ScratchDir dir;
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 320, 240, {400.0, 400.0, 160.0, 120.0});
  const Session session = SquareSession(camera);
  PbrtSceneOptions options;
  WriteSnippets(dir.str());
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
  // The Mitsuba 3 scene: the same parts, the snippets inlined, the mixes as blendbsdf, the light.
  const std::string xml = ReadText(dir / result.mitsuba_file);
  EXPECT_NE(xml.find("<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"b\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<bsdf type=\"blendbsdf\" id=\"mix-0-3-0.20\">\n    <float name=\"weight\" value=\"0.2\"/>\n"
                     "    <ref id=\"a\"/>\n    <ref id=\"b\"/>\n</bsdf>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<string name=\"filename\" value=\"../pbrt/unmeasured.ply\"/>\n    <ref id=\"unmeasured\"/>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<point name=\"position\" x=\"0.1\" y=\"0.2\" z=\"0.6\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<integer name=\"max_depth\" value=\"2\"/>"), std::string::npos) << xml;
  size_t shapes = 0;
  for (size_t at = xml.find("<shape type=\"ply\">"); at != std::string::npos;
       at = xml.find("<shape type=\"ply\">", at + 1)) {
    ++shapes;
  }
  EXPECT_EQ(shapes, 3u);
  EXPECT_EQ(ReadPly(dir / "pbrt/part-0.ply").faces.size(), 1u);
  EXPECT_EQ(ReadPly(dir / "pbrt/part-1.ply").faces.size(), 1u);
  EXPECT_EQ(ReadPly(dir / "pbrt/unmeasured.ply").faces.size(), 2u);
  EXPECT_EQ(ReadPly(dir / "pbrt/unmeasured.ply").points.size(), 4u);  // only the vertices its faces use

  const PbrtSceneResult no_pose =
      WritePbrtScene(session, 1, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir / "x", options);
  EXPECT_FALSE(no_pose.written);
  EXPECT_NE(no_pose.not_written.find("no pose"), std::string::npos);
  // The weights' sums: carried by the light's scale (their 99th percentile, at least 1) and black mixed in.
  VertexMaterials dim = Square();
  dim.scale = {0.5, 0.5, 0.0, 0.5, 0.5, 0.0};
  const PbrtSceneResult dimmed =
      WritePbrtScene(session, 0, dim, {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir.str(), options);
  EXPECT_DOUBLE_EQ(dimmed.light_scale, 1.0);
  const std::string dim_scene = ReadText(dir / dimmed.file);
  EXPECT_NE(dim_scene.find("MakeNamedMaterial \"mix-0-3-0.20-at-0.50\" \"string type\" \"mix\"\n"
                           "    \"string materials\" [ \"unmeasured\" \"mix-0-3-0.20\" ] \"float amount\" 0.5"),
            std::string::npos)
      << dim_scene;
  EXPECT_NE(dim_scene.find("\"float scale\" [ 1 ]"), std::string::npos) << dim_scene;
  EXPECT_NE(ReadText(dir / dimmed.mitsuba_file)
                .find("<bsdf type=\"blendbsdf\" id=\"mix-0-3-0.40-at-0.50\">\n    <float name=\"weight\" "
                      "value=\"0.5\"/>\n    <ref id=\"unmeasured\"/>"),
            std::string::npos);
  VertexMaterials bright = Square();
  bright.scale = {2.0, 2.0, 0.0, 1.0, 2.0, 0.0};
  const PbrtSceneResult brighter =
      WritePbrtScene(session, 0, bright, {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir.str(), options);
  // Face {0, 1, 4} sums to 2, face {0, 4, 3} to 5 / 3: the light at the 99th percentile (nearest rank)
  // of the two, the dimmer face mixed with black to 5 / 6 of it (in steps of 0.02: 0.84).
  EXPECT_DOUBLE_EQ(brighter.light_scale, 2.0);
  EXPECT_EQ(brighter.faces_scale_clipped, 0u);
  EXPECT_NE(ReadText(dir / brighter.mitsuba_file).find("<rgb name=\"intensity\" value=\"2, 2, 2\"/>"),
            std::string::npos)
      << ReadText(dir / brighter.mitsuba_file);
  EXPECT_NE(ReadText(dir / brighter.file).find("[ \"unmeasured\" \"mix-0-3-0.20\" ] \"float amount\" 0.84"),
            std::string::npos)
      << ReadText(dir / brighter.file);

  // A group without its Mitsuba 3 material: the pbrt-v4 scene alone, and why.
  WriteSnippets(dir / "y");
  std::filesystem::remove(dir / "y/group-3/b.xml");
  const PbrtSceneResult without =
      WritePbrtScene(session, 0, Square(), {"group-0/a.pbrt", "group-3/b.pbrt"}, {"a", "b"}, dir / "y", options);
  EXPECT_TRUE(without.written);
  EXPECT_TRUE(without.mitsuba_file.empty());
  EXPECT_NE(without.mitsuba_not_written.find("b.xml cannot be read"), std::string::npos) << without.mitsuba_not_written;
  EXPECT_FALSE(std::filesystem::exists(dir / "y/mitsuba/photo-0.xml"));
}

}  // namespace
}  // namespace ibrdf
