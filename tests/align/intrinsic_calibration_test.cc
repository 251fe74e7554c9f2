// Intrinsic calibration from synthetic ChArUco board photos: the camera that took them (distortion
// included) recovered within the bounds, the board's layout as OpenCV defines it, too few
// usable photos refused with the reasons, and the align stage with calibration (align/align_stage.h) end to end.
#include "align/intrinsic_calibration.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "align/align_stage.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "synth/synthetic_charuco.h"
#include "tests/error_of.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

using testing::ErrorOf;

// The largest distance, over a grid covering the image, between a pixel and where the estimated camera
// projects the true camera's ray through it. With `same_centre`, the estimate's principal point is
// replaced by the true one first: a principal point off by a pixel moves every projection by that
// pixel, which a photo's pose absorbs as a small turn, so this measures the focal lengths and the
// distortion, what the 0.3 px bound is about.
double MaxReprojectionDifference(const Camera& truth, Camera estimate, bool same_centre) {
  if (same_centre) {
    estimate.params[2] = truth.PrincipalX();
    estimate.params[3] = truth.PrincipalY();
  }
  double worst = 0.0;
  for (int gy = 0; gy <= 20; ++gy) {
    for (int gx = 0; gx <= 20; ++gx) {
      const Eigen::Vector2d pixel(0.5 + (truth.width - 1.0) * gx / 20.0, 0.5 + (truth.height - 1.0) * gy / 20.0);
      const Eigen::Vector2d xy = truth.CamPlaneFromImage(pixel);
      worst = std::max(worst, (estimate.ImageFromCamera(Eigen::Vector3d(xy.x(), xy.y(), 1.0)) - pixel).norm());
    }
  }
  return worst;
}

void ExpectWithinIssueBounds(const Camera& truth, const Camera& estimate) {
  ASSERT_EQ(estimate.model, CameraModelId::kOpenCV);
  EXPECT_NEAR(estimate.FocalX() / truth.FocalX(), 1.0, 0.005);
  EXPECT_NEAR(estimate.FocalY() / truth.FocalY(), 1.0, 0.005);
  EXPECT_NEAR(estimate.PrincipalX(), truth.PrincipalX(), 2.0);
  EXPECT_NEAR(estimate.PrincipalY(), truth.PrincipalY(), 2.0);
  EXPECT_LT(MaxReprojectionDifference(truth, estimate, /*same_centre=*/true), 0.3);
  std::cout << "focal error " << 100.0 * (estimate.FocalX() / truth.FocalX() - 1.0) << " %, "
            << 100.0 * (estimate.FocalY() / truth.FocalY() - 1.0) << " %; principal point error "
            << estimate.PrincipalX() - truth.PrincipalX() << ", " << estimate.PrincipalY() - truth.PrincipalY()
            << " px; reprojection difference " << MaxReprojectionDifference(truth, estimate, true)
            << " px (principal point included: " << MaxReprojectionDifference(truth, estimate, false) << " px)\n";
}

TEST(CharucoBoard, DefaultsAreValidAndEvenRowsAreRefused) {
  std::string why;
  EXPECT_TRUE(CharucoBoardSpec().Check(&why)) << why;
  EXPECT_TRUE(IntrinsicCalibrationOptions().Check(&why)) << why;
  EXPECT_TRUE(CharucoPhotoOptions().Check(&why)) << why;
  CharucoBoardSpec even;
  even.squares_y = 6;
  EXPECT_FALSE(even.Check(&why));
  EXPECT_NE(why.find("odd"), std::string::npos) << why;
}

// OpenCV's layout: inner corners (x + 1, y + 1) squares from the top left, x fastest; the drawn texture
// has a black square at its top left, and with an odd number of rows at its bottom left too.
TEST(CharucoBoard, LayoutAndDrawing) {
  const CharucoBoardSpec board;
  const std::vector<Eigen::Vector3d> corners = board.ChessboardCorners();
  ASSERT_EQ(corners.size(), size_t((board.squares_x - 1) * (board.squares_y - 1)));
  EXPECT_LT((corners[0] - Eigen::Vector3d(board.square_size, board.square_size, 0.0)).norm(), 1e-7);
  EXPECT_LT((corners[1] - Eigen::Vector3d(2 * board.square_size, board.square_size, 0.0)).norm(), 1e-7);
  int width = 0, height = 0;
  const std::vector<uint8_t> texels = DrawCharucoBoard(board, 20, &width, &height);
  EXPECT_EQ(width, 180);
  EXPECT_EQ(height, 140);
  EXPECT_EQ(texels[size_t(10) * width + 10], 0);           // the top-left square is black
  EXPECT_EQ(texels[size_t(10) * width + 20], 255);         // its neighbour white (the marker's margin)
  EXPECT_EQ(texels[size_t(height - 10) * width + 10], 0);  // rows are odd: the bottom-left is black too
}

// The bounds: focal length within 0.5 %, principal point within 2 px, the distortion such
// that the estimated camera reprojects the true camera's rays within 0.3 px over the whole image.
TEST(IntrinsicCalibration, RecoversTheCameraThatTookTheBoardPhotos) {
  ScratchDir dir;
  const Camera truth =
      Camera::Create(CameraModelId::kOpenCV, 640, 480, {980.0, 975.0, 325.3, 236.1, -0.08, 0.02, 0.0005, -0.0003});
  CharucoPhotoOptions options;
  options.num_photos = 12;
  ASSERT_TRUE(WriteCharucoPhotos(truth, options, dir / "board", false).success);
  EXPECT_TRUE(fs::exists(dir / "board/board.json"));
  const IntrinsicCalibrationResult result = CalibrateIntrinsics(dir / "board", IntrinsicCalibrationOptions());
  EXPECT_GE(result.views_used, 10) << result.BriefReport();
  EXPECT_LT(result.rms_px, 0.15) << result.BriefReport();
  ExpectWithinIssueBounds(truth, result.camera);
  std::cout << result.BriefReport() << "\n";
  const nlohmann::json json = ToJson(result);
  EXPECT_EQ(json["camera"]["model"], "OPENCV");
  EXPECT_EQ(json["views"].size(), 12u);
}

TEST(IntrinsicCalibration, TooFewUsablePhotosAreRefusedWithTheReasons) {
  ScratchDir dir;
  const Camera camera =
      Camera::Create(CameraModelId::kOpenCV, 320, 240, {400.0, 400.0, 160.0, 120.0, -0.05, 0.0, 0.0, 0.0});
  CharucoPhotoOptions options;
  options.num_photos = 3;
  ASSERT_TRUE(WriteCharucoPhotos(camera, options, dir / "board", false).success);
  // A photo of nothing: grey.
  Image blank(320, 240, 1);
  for (float& v : blank.pixels) v = 0.3f;
  WriteImage(dir / "board/blank.png", blank, PixelFormat::kUint8);
  std::string message = ErrorOf([&] { CalibrateIntrinsics(dir / "board", IntrinsicCalibrationOptions()); });
  EXPECT_NE(message.find("only 3 of 4 photos show enough of the board (need 5)"), std::string::npos) << message;
  EXPECT_NE(message.find("blank.png: no marker of the board found"), std::string::npos) << message;
  // A photo of another size, and a board file with an even number of rows.
  WriteImage(dir / "board/small.png", Image(100, 100, 1), PixelFormat::kUint8);
  message = ErrorOf([&] { CalibrateIntrinsics(dir / "board", IntrinsicCalibrationOptions()); });
  EXPECT_NE(message.find("small.png: is 100x100"), std::string::npos) << message;
  nlohmann::json board = ReadJsonFile(dir / "board/board.json");
  board["squares_y"] = 8;
  WriteJsonFile(dir / "board/board.json", board);
  message = ErrorOf([&] { CalibrateIntrinsics(dir / "board", IntrinsicCalibrationOptions()); });
  EXPECT_NE(message.find("board.json"), std::string::npos) << message;
  EXPECT_NE(message.find("odd"), std::string::npos) << message;
}

// End to end: synth writes board photos with the session's camera, `ibrdf align --calibrate`
// calibrates from them, aligns with the calibrated camera and writes it into the aligned session; the
// poses stay within the align stage's bounds (0.5 mm, 0.05 degrees).
TEST(IntrinsicCalibration, AlignStageCalibratesThenAligns) {
  ScratchDir dir;
  // As `ibrdf synth --targets --photos 4 --light-photos 0 --charuco-photos 24` makes it.
  SynthOptions synth;
  synth.targets.enabled = true;
  synth.rig.camera_elevation_deg = 45.0;
  synth.rig.num_photos = 4;
  synth.targets.light_photos = 0;
  testing::MakeSession(dir / "s", synth, *LoadMaterial(testing::MaterialPath("bluepaint")));
  CharucoPhotoOptions board;
  board.num_photos = 24;
  board.seed = synth.seed + 1000;
  ASSERT_TRUE(WriteCharucoPhotos(Session::Load(dir / "s").camera, board, dir / "s/calibration", false).success);
  ASSERT_TRUE(fs::exists(dir / "s/calibration/board.json"));
  AlignStageOptions options;
  options.calibration_dir = dir / "s/calibration";
  options.align.fit_sphere = false;
  SetVerbosity(1);
  ::testing::internal::CaptureStderr();
  const AlignStageResult result = AlignSessionToFolder(Session::Load(dir / "s"), options, dir / "aligned");
  const std::string log = ::testing::internal::GetCapturedStderr();
  SetVerbosity(0);
  ASSERT_TRUE(result.success);
  ASSERT_TRUE(result.calibration);
  EXPECT_NE(log.find("calibration: "), std::string::npos) << log;
  const Session truth = Session::Load(dir / "s");
  const Session aligned = Session::Load(dir / "aligned");
  ExpectWithinIssueBounds(truth.camera, aligned.camera);
  ASSERT_EQ(aligned.photos.size(), truth.photos.size());
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    const Rigid3d& expected = *truth.photos[i].camera_from_world;
    const Rigid3d& estimated = *aligned.photos[i].camera_from_world;
    EXPECT_LT((estimated.Inverse().translation - expected.Inverse().translation).norm(), 0.5e-3) << "photo " << i;
    EXPECT_LT(estimated.rotation.angularDistance(expected.rotation) * 180.0 / M_PI, 0.05) << "photo " << i;
  }
  const nlohmann::json report = ReadJsonFile(dir / "aligned/alignment.json");
  EXPECT_GT(report["intrinsic_calibration"]["views_used"].get<int>(), 8);
}

}  // namespace
}  // namespace ibrdf
