#include "core/camera.h"

#include <cmath>

#include <Eigen/LU>

#include "core/error.h"
#include "core/kind.h"

namespace ibrdf {
namespace {

struct ModelInfo {
  CameraModelId id;
  const char* name;
  int num_params;
};

constexpr ModelInfo kModels[] = {
    {CameraModelId::kSimplePinhole, "SIMPLE_PINHOLE", 3},
    {CameraModelId::kPinhole, "PINHOLE", 4},
    {CameraModelId::kSimpleRadial, "SIMPLE_RADIAL", 4},
    {CameraModelId::kRadial, "RADIAL", 5},
    {CameraModelId::kOpenCV, "OPENCV", 8},
};

const ModelInfo& Info(CameraModelId id) {
  for (const ModelInfo& info : kModels) {
    if (info.id == id) return info;
  }
  IBRDF_CHECK(false) << "unknown camera model id";
  return kModels[0];
}

// Whether the model's parameters start fx, fy, cx, cy (PINHOLE, OPENCV) rather than f, cx, cy (COLMAP's
// parameter order).
bool HasTwoFocalLengths(CameraModelId model) {
  switch (model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kSimpleRadial:
    case CameraModelId::kRadial:
      return false;
    case CameraModelId::kPinhole:
    case CameraModelId::kOpenCV:
      return true;
  }
  UnhandledKind("CameraModelId", static_cast<int>(model));
}

// Distortion coefficients in OpenCV's form (k1, k2, p1, p2), zero where the model has none.
struct Coefficients {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
};

Coefficients CoefficientsOf(const Camera& camera) {
  const std::vector<double>& p = camera.params;
  Coefficients c;
  switch (camera.model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kPinhole:
      break;
    case CameraModelId::kSimpleRadial:
      c.k1 = p[3];
      break;
    case CameraModelId::kRadial:
      c.k1 = p[3];
      c.k2 = p[4];
      break;
    case CameraModelId::kOpenCV:
      c.k1 = p[4];
      c.k2 = p[5];
      c.p1 = p[6];
      c.p2 = p[7];
      break;
  }
  return c;
}

// Distorted point and its Jacobian with respect to the undistorted point.
Eigen::Vector2d DistortWithJacobian(const Coefficients& c, const Eigen::Vector2d& xy, Eigen::Matrix2d* jacobian) {
  const double x = xy.x(), y = xy.y();
  const double x2 = x * x, y2 = y * y, xy_ = x * y;
  const double r2 = x2 + y2;
  const double radial = 1.0 + c.k1 * r2 + c.k2 * r2 * r2;
  const double dradial_dr2 = c.k1 + 2.0 * c.k2 * r2;
  const Eigen::Vector2d out(x * radial + 2.0 * c.p1 * xy_ + c.p2 * (r2 + 2.0 * x2),
                            y * radial + c.p1 * (r2 + 2.0 * y2) + 2.0 * c.p2 * xy_);
  if (jacobian) {
    (*jacobian)(0, 0) = radial + x * dradial_dr2 * 2.0 * x + 2.0 * c.p1 * y + c.p2 * 6.0 * x;
    (*jacobian)(0, 1) = x * dradial_dr2 * 2.0 * y + 2.0 * c.p1 * x + c.p2 * 2.0 * y;
    (*jacobian)(1, 0) = y * dradial_dr2 * 2.0 * x + c.p1 * 2.0 * x + 2.0 * c.p2 * y;
    (*jacobian)(1, 1) = radial + y * dradial_dr2 * 2.0 * y + c.p1 * 6.0 * y + 2.0 * c.p2 * x;
  }
  return out;
}

}  // namespace

const char* CameraModelName(CameraModelId id) { return Info(id).name; }

bool CameraModelFromName(const std::string& name, CameraModelId* id) {
  for (const ModelInfo& info : kModels) {
    if (name == info.name) {
      *id = info.id;
      return true;
    }
  }
  return false;
}

int CameraModelNumParams(CameraModelId id) { return Info(id).num_params; }

Camera Camera::Create(CameraModelId model, int width, int height, std::vector<double> params,
                      const std::string& where) {
  Camera camera;
  camera.model = model;
  camera.width = width;
  camera.height = height;
  camera.params = std::move(params);
  std::string why;
  if (!camera.Check(&why)) ThrowError(where, why);
  return camera;
}

double Camera::FocalX() const { return params[0]; }
double Camera::FocalY() const { return HasTwoFocalLengths(model) ? params[1] : params[0]; }
double Camera::PrincipalX() const { return HasTwoFocalLengths(model) ? params[2] : params[1]; }
double Camera::PrincipalY() const { return HasTwoFocalLengths(model) ? params[3] : params[2]; }

bool Camera::HasDistortion() const {
  const Coefficients c = CoefficientsOf(*this);
  return c.k1 != 0 || c.k2 != 0 || c.p1 != 0 || c.p2 != 0;
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& undistorted) const {
  return DistortWithJacobian(CoefficientsOf(*this), undistorted, nullptr);
}

Eigen::Vector2d Camera::ImageFromCamera(const Eigen::Vector3d& p_in_camera) const {
  const Eigen::Vector2d xy = p_in_camera.head<2>() / p_in_camera.z();
  const Eigen::Vector2d d = Distort(xy);
  return {FocalX() * d.x() + PrincipalX(), FocalY() * d.y() + PrincipalY()};
}

Eigen::Vector2d Camera::CamPlaneFromImage(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d distorted((pixel.x() - PrincipalX()) / FocalX(), (pixel.y() - PrincipalY()) / FocalY());
  const Coefficients c = CoefficientsOf(*this);
  if (c.k1 == 0 && c.k2 == 0 && c.p1 == 0 && c.p2 == 0) return distorted;
  // Newton's method on Distort(x) = distorted, started at the distorted point.
  Eigen::Vector2d x = distorted;
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::Matrix2d jacobian;
    const Eigen::Vector2d residual = DistortWithJacobian(c, x, &jacobian) - distorted;
    if (residual.squaredNorm() < 1e-30) break;
    const double det = jacobian(0, 0) * jacobian(1, 1) - jacobian(0, 1) * jacobian(1, 0);
    if (!(std::abs(det) > 1e-300)) break;
    const Eigen::Vector2d step((jacobian(1, 1) * residual.x() - jacobian(0, 1) * residual.y()) / det,
                               (-jacobian(1, 0) * residual.x() + jacobian(0, 0) * residual.y()) / det);
    if (!step.allFinite()) break;
    x -= step;
    if (step.squaredNorm() < 1e-30) break;
  }
  return x;
}

bool Camera::Check(std::string* why) const {
  const int expected = CameraModelNumParams(model);
  if (static_cast<int>(params.size()) != expected) {
    *why = std::string(CameraModelName(model)) + " takes " + std::to_string(expected) + " parameters, got " +
           std::to_string(params.size());
    return false;
  }
  IBRDF_CHECK_OPTION_GT(width, 0);
  IBRDF_CHECK_OPTION_GT(height, 0);
  for (size_t i = 0; i < params.size(); ++i) {
    if (!std::isfinite(params[i])) {
      *why = "params[" + std::to_string(i) + "] must be a finite number, got " + std::to_string(params[i]);
      return false;
    }
  }
  IBRDF_CHECK_OPTION_GT(FocalX(), 0.0);
  IBRDF_CHECK_OPTION_GT(FocalY(), 0.0);
  return true;
}

}  // namespace ibrdf
