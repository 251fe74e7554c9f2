// Tests of core/camera.h: the COLMAP camera models, their validation, projection and its inverse.
#include "core/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ibrdf {
namespace {

constexpr CameraModelId kAllModels[] = {CameraModelId::kSimplePinhole, CameraModelId::kPinhole,
                                        CameraModelId::kSimpleRadial, CameraModelId::kRadial, CameraModelId::kOpenCV};

// A valid parameter list for each model (focal 3000 px, principal point at the image centre).
std::vector<double> ValidParams(CameraModelId model) {
  switch (model) {
    case CameraModelId::kSimplePinhole:
      return {3000, 400, 300};
    case CameraModelId::kPinhole:
      return {3000, 3010, 400, 300};
    case CameraModelId::kSimpleRadial:
      return {3000, 400, 300, -0.08};
    case CameraModelId::kRadial:
      return {3000, 400, 300, -0.08, 0.02};
    case CameraModelId::kOpenCV:
      return {3000, 3000, 400, 300, -0.08, 0.02, 5e-4, -3e-4};
  }
  return {};
}

// Pixel positions on a grid of `step` pixels covering the whole image, corners and edges included.
std::vector<Eigen::Vector2d> PixelsCoveringImage(const Camera& camera, double step) {
  std::vector<Eigen::Vector2d> pixels;
  for (double row = 0.0; row <= camera.height + 1e-9; row += step) {
    for (double col = 0.0; col <= camera.width + 1e-9; col += step) pixels.emplace_back(col, row);
  }
  return pixels;
}

// Unprojecting a pixel and projecting the ray again gives the pixel back (to 1e-9 px), projecting the
// plane point and unprojecting it gives the point back (to 1e-12, the accuracy camera.h promises), and
// every point along the ray projects to the same pixel.
void ExpectRoundTrip(const Camera& camera) {
  const std::vector<Eigen::Vector2d> pixels = PixelsCoveringImage(camera, 10.0);
  ASSERT_GT(pixels.size(), 4000u);
  double max_pixel_error = 0.0, max_plane_error = 0.0, max_depth_error = 0.0;
  for (const Eigen::Vector2d& pixel : pixels) {
    const Eigen::Vector2d xy = camera.CamPlaneFromImage(pixel);
    ASSERT_TRUE(xy.allFinite()) << pixel.transpose();
    const Eigen::Vector2d reprojected = camera.ImageFromCamera(Eigen::Vector3d(xy.x(), xy.y(), 1.0));
    max_pixel_error = std::max(max_pixel_error, (reprojected - pixel).norm());
    max_plane_error = std::max(max_plane_error, (camera.CamPlaneFromImage(reprojected) - xy).norm());
    const Eigen::Vector2d far = camera.ImageFromCamera(Eigen::Vector3d(7 * xy.x(), 7 * xy.y(), 7.0));
    max_depth_error = std::max(max_depth_error, (far - reprojected).norm());
  }
  EXPECT_LT(max_pixel_error, 1e-9) << CameraModelName(camera.model);
  EXPECT_LT(max_plane_error, 1e-12) << CameraModelName(camera.model);
  EXPECT_LT(max_depth_error, 1e-9) << CameraModelName(camera.model);
}

// The parameter counts of COLMAP's cameras.txt.
TEST(Camera, ParamCountsMatchColmap) {
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kSimplePinhole), 3);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kPinhole), 4);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kSimpleRadial), 4);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kRadial), 5);
  EXPECT_EQ(CameraModelNumParams(CameraModelId::kOpenCV), 8);
}

// Names round-trip through CameraModelFromName; models ibrdf does not support are refused.
TEST(Camera, ModelNamesRoundTrip) {
  for (CameraModelId model : kAllModels) {
    CameraModelId parsed = CameraModelId::kPinhole;
    ASSERT_TRUE(CameraModelFromName(CameraModelName(model), &parsed)) << CameraModelName(model);
    EXPECT_EQ(parsed, model);
  }
  EXPECT_STREQ(CameraModelName(CameraModelId::kOpenCV), "OPENCV");
  EXPECT_STREQ(CameraModelName(CameraModelId::kSimpleRadial), "SIMPLE_RADIAL");
  CameraModelId unused;
  EXPECT_FALSE(CameraModelFromName("FULL_OPENCV", &unused));
  EXPECT_FALSE(CameraModelFromName("opencv", &unused));
  EXPECT_FALSE(CameraModelFromName("", &unused));
}

TEST(Camera, CreateAcceptsValidParams) {
  for (CameraModelId model : kAllModels) {
    EXPECT_NO_THROW(Camera::Create(model, 800, 600, ValidParams(model))) << CameraModelName(model);
  }
}

TEST(Camera, AccessorsFollowColmapParameterOrder) {
  const Camera pinhole = Camera::Create(CameraModelId::kPinhole, 800, 600, {3000, 3010, 401, 299});
  EXPECT_EQ(pinhole.FocalX(), 3000);
  EXPECT_EQ(pinhole.FocalY(), 3010);
  EXPECT_EQ(pinhole.PrincipalX(), 401);
  EXPECT_EQ(pinhole.PrincipalY(), 299);
  EXPECT_FALSE(pinhole.HasDistortion());
  const Camera radial = Camera::Create(CameraModelId::kRadial, 800, 600, {2000, 401, 299, 0.0, 0.01});
  EXPECT_EQ(radial.FocalX(), 2000);
  EXPECT_EQ(radial.FocalY(), 2000);
  EXPECT_EQ(radial.PrincipalX(), 401);
  EXPECT_EQ(radial.PrincipalY(), 299);
  EXPECT_TRUE(radial.HasDistortion());
  const Camera opencv = Camera::Create(CameraModelId::kOpenCV, 800, 600, ValidParams(CameraModelId::kOpenCV));
  EXPECT_EQ(opencv.PrincipalX(), 400);
  EXPECT_EQ(opencv.PrincipalY(), 300);
  EXPECT_TRUE(opencv.HasDistortion());
}

// One parameter too few or too many is an Error naming the source, for every model.
TEST(Camera, CreateRejectsWrongParamCount) {
  for (CameraModelId model : kAllModels) {
    std::vector<double> fewer = ValidParams(model);
    fewer.pop_back();
    std::vector<double> more = ValidParams(model);
    more.push_back(0.0);
    EXPECT_THROW(Camera::Create(model, 800, 600, fewer), Error) << CameraModelName(model);
    EXPECT_THROW(Camera::Create(model, 800, 600, more), Error) << CameraModelName(model);
    EXPECT_THROW(Camera::Create(model, 800, 600, {}), Error) << CameraModelName(model);
  }
  try {
    Camera::Create(CameraModelId::kPinhole, 800, 600, {3000, 400, 300}, "cameras.txt: camera 1");
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.txt: camera 1"), std::string::npos) << e.what();
  }
}

// A focal length must be positive: zero or negative fx or fy is an Error.
TEST(Camera, CreateRejectsNonPositiveFocal) {
  EXPECT_THROW(Camera::Create(CameraModelId::kSimplePinhole, 800, 600, {0, 400, 300}), Error);
  EXPECT_THROW(Camera::Create(CameraModelId::kSimplePinhole, 800, 600, {-3000, 400, 300}), Error);
  EXPECT_THROW(Camera::Create(CameraModelId::kPinhole, 800, 600, {3000, 0, 400, 300}), Error);
  EXPECT_THROW(Camera::Create(CameraModelId::kPinhole, 800, 600, {-1, 3000, 400, 300}), Error);
  EXPECT_THROW(Camera::Create(CameraModelId::kOpenCV, 800, 600, {3000, -3000, 400, 300, 0, 0, 0, 0}), Error);
}

// An image needs a positive width and height.
TEST(Camera, CreateRejectsEmptyImage) {
  for (CameraModelId model : kAllModels) {
    EXPECT_THROW(Camera::Create(model, 0, 600, ValidParams(model)), Error) << CameraModelName(model);
    EXPECT_THROW(Camera::Create(model, 800, 0, ValidParams(model)), Error) << CameraModelName(model);
    EXPECT_THROW(Camera::Create(model, -800, 600, ValidParams(model)), Error) << CameraModelName(model);
  }
}

// NaN or infinity in any parameter slot is an Error (NaN fails every comparison, so it needs its
// own check).
TEST(Camera, CreateRejectsNonFiniteParams) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (CameraModelId model : kAllModels) {
    const std::vector<double> valid = ValidParams(model);
    for (size_t i = 0; i < valid.size(); ++i) {
      for (double bad : {nan, inf, -inf}) {
        std::vector<double> params = valid;
        params[i] = bad;
        EXPECT_THROW(Camera::Create(model, 800, 600, params), Error)
            << CameraModelName(model) << " param " << i << " = " << bad;
      }
    }
  }
}

// Check() says why a hand-built camera is invalid.
TEST(Camera, CheckExplainsFailure) {
  Camera camera;
  camera.model = CameraModelId::kPinhole;
  camera.width = 800;
  camera.height = 600;
  camera.params = {3000, 3000, 400};
  std::string why;
  EXPECT_FALSE(camera.Check(&why));
  EXPECT_NE(why.find("PINHOLE"), std::string::npos) << why;
  camera.params.push_back(300);
  why.clear();
  EXPECT_TRUE(camera.Check(&why)) << why;
}

// COLMAP's pixel convention: a point on the optical axis projects to (cx, cy), and with the principal
// point at (width/2, height/2) the centres of the first and last pixel of a row, 0.5 and width - 0.5,
// lie symmetrically about the axis.
TEST(Camera, PixelCentreConvention) {
  for (CameraModelId model : kAllModels) {
    const Camera camera = Camera::Create(model, 800, 600, ValidParams(model));
    const Eigen::Vector2d on_axis = camera.ImageFromCamera(Eigen::Vector3d(0, 0, 2.5));
    EXPECT_NEAR(on_axis.x(), camera.PrincipalX(), 1e-12) << CameraModelName(model);
    EXPECT_NEAR(on_axis.y(), camera.PrincipalY(), 1e-12) << CameraModelName(model);
    const Eigen::Vector2d axis = camera.CamPlaneFromImage(Eigen::Vector2d(400, 300));
    EXPECT_NEAR(axis.norm(), 0.0, 1e-15) << CameraModelName(model);
    const Eigen::Vector2d first = camera.CamPlaneFromImage(Eigen::Vector2d(0.5, 0.5));
    const Eigen::Vector2d last = camera.CamPlaneFromImage(Eigen::Vector2d(799.5, 599.5));
    // Radial distortion is point-symmetric about the axis (OPENCV's tangential terms are not).
    if (model != CameraModelId::kOpenCV) {
      EXPECT_NEAR(first.x(), -last.x(), 1e-15) << CameraModelName(model);
      EXPECT_NEAR(first.y(), -last.y(), 1e-15) << CameraModelName(model);
    }
  }
  // Without distortion the pixel-centre offset is exact: pixel (0, 0) has its centre at (0.5, 0.5).
  const Camera pinhole = Camera::Create(CameraModelId::kPinhole, 800, 600, {1000, 1000, 400, 300});
  const Eigen::Vector2d corner_centre = pinhole.CamPlaneFromImage(Eigen::Vector2d(0.5, 0.5));
  EXPECT_DOUBLE_EQ(corner_centre.x(), -399.5 / 1000);
  EXPECT_DOUBLE_EQ(corner_centre.y(), -299.5 / 1000);
}

// Pinhole projection is x = f X / Z + c; image y grows downwards with camera y.
TEST(Camera, PinholeProjectionFormula) {
  const Camera camera = Camera::Create(CameraModelId::kPinhole, 800, 600, {1000, 1200, 400, 300});
  const Eigen::Vector2d pixel = camera.ImageFromCamera(Eigen::Vector3d(0.1, 0.2, 2.0));
  EXPECT_DOUBLE_EQ(pixel.x(), 1000 * 0.05 + 400);
  EXPECT_DOUBLE_EQ(pixel.y(), 1200 * 0.1 + 300);
}

// The distortion formulas themselves at one point, against a hand computation (OpenCV's
// radial-tangential model; COLMAP's SIMPLE_RADIAL and RADIAL are its radial part).
TEST(Camera, DistortionMatchesOpenCvFormula) {
  const double k1 = -0.08, k2 = 0.02, p1 = 5e-4, p2 = -3e-4;
  const Camera camera = Camera::Create(CameraModelId::kOpenCV, 800, 600, {3000, 3000, 400, 300, k1, k2, p1, p2});
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  const double radial = 1 + k1 * r2 + k2 * r2 * r2;
  const Eigen::Vector2d expected(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
                                 y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y);
  EXPECT_NEAR((camera.Distort(Eigen::Vector2d(x, y)) - expected).norm(), 0.0, 1e-15);

  const Camera radial_camera = Camera::Create(CameraModelId::kRadial, 800, 600, {3000, 400, 300, k1, k2});
  EXPECT_NEAR((radial_camera.Distort(Eigen::Vector2d(x, y)) - Eigen::Vector2d(x, y) * radial).norm(), 0.0, 1e-15);
  const Camera simple = Camera::Create(CameraModelId::kSimpleRadial, 800, 600, {3000, 400, 300, k1});
  EXPECT_NEAR((simple.Distort(Eigen::Vector2d(x, y)) - Eigen::Vector2d(x, y) * (1 + k1 * r2)).norm(), 0.0, 1e-15);
}

// Unprojection inverts projection over the whole image, for the realistic lens of the brief.
TEST(Camera, OpenCvRoundTripOverWholeImage) {
  ExpectRoundTrip(Camera::Create(CameraModelId::kOpenCV, 800, 600, {3000, 3000, 400, 300, -0.08, 0.02, 5e-4, -3e-4}));
}

TEST(Camera, RadialRoundTripOverWholeImage) {
  ExpectRoundTrip(Camera::Create(CameraModelId::kSimpleRadial, 800, 600, {3000, 400, 300, -0.08}));
  ExpectRoundTrip(Camera::Create(CameraModelId::kRadial, 800, 600, {3000, 400, 300, -0.08, 0.02}));
}

// A wide-angle lens (normalized radius up to 0.83) with strong distortion still inverts exactly.
TEST(Camera, WideAngleRoundTripOverWholeImage) {
  ExpectRoundTrip(Camera::Create(CameraModelId::kOpenCV, 800, 600, {600, 600, 400, 300, -0.08, 0.02, 5e-4, -3e-4}));
  ExpectRoundTrip(Camera::Create(CameraModelId::kRadial, 800, 600, {600, 400, 300, -0.08, 0.02}));
}

// Without distortion unprojection is the exact affine inverse.
TEST(Camera, PinholeRoundTripOverWholeImage) {
  ExpectRoundTrip(Camera::Create(CameraModelId::kSimplePinhole, 800, 600, {3000, 400, 300}));
  ExpectRoundTrip(Camera::Create(CameraModelId::kPinhole, 800, 600, {3000, 2990, 410, 290}));
}

}  // namespace
}  // namespace ibrdf
