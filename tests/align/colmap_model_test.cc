// COLMAP models: the real test model reads identically from binary and text, camera centres match an
// independent computation from images.txt, and corrupt or unsupported input is a clear error.
#include "align/colmap_model.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

const std::string kModel = std::string(IBRDF_SHARED_DATA_DIR) + "/colmap-test-model";

#define REQUIRE_SHARED_DATA()                                                             \
  if (!fs::exists(kModel + "/sparse/0/cameras.bin")) {                                    \
    GTEST_SKIP() << "../shared/data/colmap-test-model is absent: real-data test skipped"; \
  }

using testing::ErrorOf;

TEST(ColmapModel, BinaryAndTextAgree) {
  REQUIRE_SHARED_DATA();
  const ColmapModel binary = ColmapModel::Read(kModel + "/sparse/0");
  const ColmapModel text = ColmapModel::Read(kModel + "/sparse-txt/0");
  ASSERT_EQ(binary.cameras.size(), 23u);
  ASSERT_EQ(binary.images.size(), 23u);
  ASSERT_EQ(binary.cameras.size(), text.cameras.size());
  ASSERT_EQ(binary.images.size(), text.images.size());
  ASSERT_EQ(binary.points.size(), text.points.size());
  ASSERT_GT(binary.points.size(), 1000u);
  for (const auto& [id, camera] : binary.cameras) {
    const Camera& other = text.cameras.at(id);
    EXPECT_EQ(camera.model, CameraModelId::kSimpleRadial);
    EXPECT_EQ(camera.width, 3031);
    EXPECT_EQ(camera.height, 2006);
    for (size_t p = 0; p < camera.params.size(); ++p) EXPECT_NEAR(camera.params[p], other.params[p], 1e-9);
  }
  for (const auto& [id, image] : binary.images) {
    const ColmapImage& other = text.images.at(id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.camera_id, other.camera_id);
    EXPECT_LT(image.camera_from_world.rotation.angularDistance(other.camera_from_world.rotation), 1e-12);
    EXPECT_LT((image.camera_from_world.translation - other.camera_from_world.translation).norm(), 1e-12);
    ASSERT_EQ(image.points2d.size(), other.points2d.size());
    EXPECT_EQ(image.point3d_ids, other.point3d_ids);
  }
  for (const auto& [id, point] : binary.points) {
    const ColmapPoint3D& other = text.points.at(id);
    EXPECT_LT((point.xyz - other.xyz).norm(), 1e-9);
    EXPECT_EQ(point.track, other.track);
  }
}

// Camera centres C = -R^T t from images.txt, with the rotation matrix written out from the quaternion
// by hand (no Eigen quaternion), against the reader's.
TEST(ColmapModel, CameraCentresMatchImagesTxt) {
  REQUIRE_SHARED_DATA();
  const ColmapModel binary = ColmapModel::Read(kModel + "/sparse/0");
  std::ifstream in(kModel + "/sparse-txt/0/images.txt");
  std::string line;
  int checked = 0;
  bool pose_line = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!pose_line) {
      pose_line = true;
      continue;
    }
    pose_line = false;
    std::istringstream fields(line);
    uint32_t id;
    double w, x, y, z, t[3];
    fields >> id >> w >> x >> y >> z >> t[0] >> t[1] >> t[2];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    Eigen::Vector3d center;
    for (int i = 0; i < 3; ++i) center[i] = -(r[0][i] * t[0] + r[1][i] * t[1] + r[2][i] * t[2]);
    EXPECT_LT((binary.images.at(id).Center() - center).norm(), 1e-9) << "image " << id;
    ++checked;
  }
  EXPECT_EQ(checked, 23);
}

class CorruptModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kModel + "/sparse/0/cameras.bin")) GTEST_SKIP() << "../shared/data is absent";
    for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
      fs::copy_file(kModel + "/sparse/0/" + name, dir_ / name);
      fs::permissions(dir_ / name, fs::perms::owner_read | fs::perms::owner_write);
    }
  }
  ScratchDir dir_;
};

TEST_F(CorruptModelTest, TruncatedImagesBin) {
  fs::resize_file(dir_ / "images.bin", fs::file_size(dir_ / "images.bin") / 2);
  const std::string message = ErrorOf([&] { ColmapModel::Read(dir_.str()); });
  EXPECT_NE(message.find("images.bin"), std::string::npos) << message;
  // Cut mid-record, the reader finds either a short read or a count the rest cannot hold.
  EXPECT_TRUE(message.find("truncated") != std::string::npos || message.find("does not fit") != std::string::npos)
      << message;
}

TEST_F(CorruptModelTest, ImpossibleCountIsCaughtBeforeAllocating) {
  std::fstream file(dir_ / "points3D.bin", std::ios::in | std::ios::out | std::ios::binary);
  const uint64_t huge = uint64_t(1) << 60;
  file.write(reinterpret_cast<const char*>(&huge), sizeof(huge));
  file.close();
  const std::string message = ErrorOf([&] { ColmapModel::Read(dir_.str()); });
  EXPECT_NE(message.find("points3D.bin"), std::string::npos) << message;
  EXPECT_NE(message.find("corrupt"), std::string::npos) << message;
}

TEST_F(CorruptModelTest, UnsupportedCameraModel) {
  // The first camera's model id sits after the count (8 bytes) and its id (4 bytes); 5 is OPENCV_FISHEYE.
  std::fstream file(dir_ / "cameras.bin", std::ios::in | std::ios::out | std::ios::binary);
  file.seekp(12);
  const int32_t fisheye = 5;
  file.write(reinterpret_cast<const char*>(&fisheye), sizeof(fisheye));
  file.close();
  const std::string message = ErrorOf([&] { ColmapModel::Read(dir_.str()); });
  EXPECT_NE(message.find("OPENCV_FISHEYE"), std::string::npos) << message;
  EXPECT_NE(message.find("cameras.bin"), std::string::npos) << message;
}

TEST(ColmapModelText, UnknownModelAndDanglingReferences) {
  ScratchDir dir;
  std::ofstream(dir / "cameras.txt") << "# comment\n1 FULL_OPENCV 640 480 500 500 320 240 0 0 0 0 0 0 0 0\n";
  std::ofstream(dir / "images.txt") << "";
  std::ofstream(dir / "points3D.txt") << "";
  std::string message = ErrorOf([&] { ColmapModel::Read(dir.str()); });
  EXPECT_NE(message.find("cameras.txt:2"), std::string::npos) << message;
  EXPECT_NE(message.find("FULL_OPENCV"), std::string::npos) << message;

  std::ofstream(dir / "cameras.txt") << "1 PINHOLE 640 480 500 500 320 240\n";
  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 0 7 a.jpg\n10 20 -1\n";
  message = ErrorOf([&] { ColmapModel::Read(dir.str()); });
  EXPECT_NE(message.find("missing camera 7"), std::string::npos) << message;

  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 0 1 a.jpg\n10 20 -1\n2 1 0 0 0 0 0 1 1 b.jpg\n\n";
  std::ofstream(dir / "points3D.txt") << "5 0 0 1 255 0 0 0.5 1 0 2 0\n";
  message = ErrorOf([&] { ColmapModel::Read(dir.str()); });
  EXPECT_NE(message.find("(2, 0) that names no 2D point"), std::string::npos) << message;

  std::ofstream(dir / "points3D.txt") << "5 0 0 1 255 0 0 0.5 1 0\n";
  const ColmapModel model = ColmapModel::Read(dir.str());
  EXPECT_EQ(model.images.size(), 2u);
  EXPECT_EQ(model.images.at(1).points2d.size(), 1u);
  EXPECT_EQ(model.images.at(2).points2d.size(), 0u);
  EXPECT_EQ(model.points.at(5).track.size(), 1u);
}

// The text reader once took "12x.5" as 12, "0.1" in an integer field as 0, ignored extra fields
// and NaN, and let std::stod/std::stoll throw bare messages. Each is now one line naming file:line.
TEST(ColmapModelText, NumbersAreWholeTokensAndFinite) {
  ScratchDir dir;
  const std::string cameras = "1 SIMPLE_RADIAL 640 480 500 320 240 0.01\n";
  const std::string images = "1 1 0 0 0 0.1 0 1 1 a.jpg\n10 20 1 30 40 -1\n";
  const std::string points = "1 0.5 0.2 3 10 20 30 0.7 1 0\n";
  auto write = [&](const std::string& c, const std::string& i, const std::string& p) {
    std::ofstream(dir / "cameras.txt") << c;
    std::ofstream(dir / "images.txt") << i;
    std::ofstream(dir / "points3D.txt") << p;
  };
  write(cameras, images, points);
  EXPECT_EQ(ColmapModel::ReadText(dir.str()).points.size(), 1u);  // the base case reads
  const struct {
    std::string cameras, images, points, file, expected;
  } cases[] = {
      {cameras, "1 1 0 0 0 12x.5 0 1 1 a.jpg\n10 20 1 30 40 -1\n", points, "images.txt:1", "'12x.5' is not a number"},
      {"1 SIMPLE_RADIAL 0.1 480 500 320 240 0.01\n", images, points, "cameras.txt:1", "'0.1' is not a non-negative"},
      {"1 SIMPLE_RADIAL 640 480 500 320 240 0.01 7\n", images, points, "cameras.txt:1", "has 4 parameters"},
      {"1 SIMPLE_RADIAL 640 480 500 320 240\n", images, points, "cameras.txt:1", "has 4 parameters"},
      {cameras, "1 1 0 0 0 0.1 0 1 1 a.jpg extra\n10 20 1\n", points, "images.txt:1", "10 fields"},
      {cameras, images, "1 nan 0.2 3 10 20 30 0.7 1 0\n", "points3D.txt:1", "not finite"},
      {cameras, images, "1 0.5 0.2 3 10 20 30 0.7 1\n", "points3D.txt:1", "pairs"},
      {cameras, "1 1 0 0 0 1e999 0 1 1 a.jpg\n10 20 1\n", points, "images.txt:1", "not finite"},
      {cameras, "1 1 0 0 0 0.1 0 1 1 a.jpg\n10 20 99999999999999999999\n", points, "images.txt:2", "out of range"},
      {cameras, images, "1 0.5 0.2 3 10 20 300 0.7 1 0\n", "points3D.txt:1", "colour 300 is out of range"},
  };
  for (const auto& c : cases) {
    write(c.cameras, c.images, c.points);
    const std::string message = ErrorOf([&] { ColmapModel::ReadText(dir.str()); });
    EXPECT_NE(message.find(c.file), std::string::npos) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.expected << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace ibrdf
