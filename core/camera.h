// Camera intrinsics: the COLMAP camera models that calibrated cameras need.
//
// Pixel coordinates follow COLMAP: the upper-left corner of the image is (0, 0), so the centre of
// pixel (col, row) is (col + 0.5, row + 0.5). Camera axes: x right, y down, z forward.
// Parameter lists, in COLMAP's order:
//   SIMPLE_PINHOLE f, cx, cy
//   PINHOLE        fx, fy, cx, cy
//   SIMPLE_RADIAL  f, cx, cy, k
//   RADIAL         f, cx, cy, k1, k2
//   OPENCV         fx, fy, cx, cy, k1, k2, p1, p2   (OpenCV's radial-tangential distortion)
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/kind.h"

namespace ibrdf {

enum class CameraModelId { kSimplePinhole, kPinhole, kSimpleRadial, kRadial, kOpenCV, IBRDF_DUMMY_KIND };

// "OPENCV" for kOpenCV; the names of COLMAP's cameras.txt.
const char* CameraModelName(CameraModelId id);
// Parses a COLMAP model name; false for models ibrdf does not support.
bool CameraModelFromName(const std::string& name, CameraModelId* id);
// Number of parameters of the model.
int CameraModelNumParams(CameraModelId id);

struct Camera {
  CameraModelId model = CameraModelId::kPinhole;
  int width = 0;   // pixels
  int height = 0;  // pixels
  std::vector<double> params;

  // Builds and validates a camera; throws Error naming `where` if the parameters do not fit the model.
  static Camera Create(CameraModelId model, int width, int height, std::vector<double> params,
                       const std::string& where = "camera");

  double FocalX() const;
  double FocalY() const;
  double PrincipalX() const;
  double PrincipalY() const;
  bool HasDistortion() const;

  // Projects a point in the camera frame (z > 0) to pixel coordinates, distortion included.
  Eigen::Vector2d ImageFromCamera(const Eigen::Vector3d& p_in_camera) const;

  // The undistorted normalized image-plane point (x, y) with (x, y, 1) along the ray through `pixel`.
  // Inverts the distortion iteratively (Newton with an analytic Jacobian); accurate to 1e-12 inside
  // the image for realistic distortion.
  Eigen::Vector2d CamPlaneFromImage(const Eigen::Vector2d& pixel) const;

  // Applies the model's distortion to an undistorted normalized point.
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted) const;

  // Checks the parameters; on failure returns false and says why.
  bool Check(std::string* why) const;
};

}  // namespace ibrdf
