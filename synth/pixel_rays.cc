#include "synth/pixel_rays.h"

namespace ibrdf {

CameraRay::CameraRay(const Camera& camera, const Rigid3d& camera_from_world) : camera_(camera) {
  const Rigid3d world_from_camera = camera_from_world.Inverse();
  world_from_camera_ = world_from_camera.rotation.toRotationMatrix();
  eye_ = world_from_camera.translation;
}

Eigen::Vector3d CameraRay::Direction(const Eigen::Vector2d& pixel) const {
  return DirectionOfCamPlane(camera_.CamPlaneFromImage(pixel));
}

PixelRays::PixelRays(const Camera& camera, int supersample)
    : width_(camera.width), height_(camera.height), supersample_(supersample) {
  const int n = supersample_;
  xy_.resize(size_t(width_) * height_ * n * n);
  tbb::parallel_for(0, height_, [&](int y) {
    for (int x = 0; x < width_; ++x) {
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          xy_[((size_t(y) * width_ + x) * n + sy) * n + sx] =
              camera.CamPlaneFromImage(Eigen::Vector2d(x + (sx + 0.5) / n, y + (sy + 0.5) / n));
        }
      }
    }
  });
}

}  // namespace ibrdf
