// The rays of a synthetic camera (the one ray loop behind synth's renders: the sample, the white
// reference and its marker card, the colour chart): a pixel's world ray, the camera's undistorted
// sub-pixel directions computed once and shared by every photo taken with it, and a supersampled render
// loop that calls a shading function per ray.
#pragma once

#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Core>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/rigid3.h"

namespace ibrdf {

// Where a ray from `origin` along `direction` meets the front of the plane through `center` with unit
// normal `normal` (the side the normal faces): true with the ray parameter in `t` (> 0); false for a
// ray parallel to the plane or arriving from behind it, or a plane behind the ray's origin.
inline bool RayPlaneHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& center,
                        const Eigen::Vector3d& normal, double* t) {
  const double denominator = direction.dot(normal);
  if (!(denominator < 0.0)) return false;
  *t = (center - origin).dot(normal) / denominator;
  return *t > 0.0;
}

// A camera at a pose: the world ray through any image point (pixel centres at +0.5), undistorted with
// Camera::CamPlaneFromImage (Newton iterations: the slow path, for the rays no table holds).
class CameraRay {
 public:
  CameraRay(const Camera& camera, const Rigid3d& camera_from_world);

  // The camera's centre in the world (every ray's origin).
  const Eigen::Vector3d& eye() const { return eye_; }
  // The unit world direction through image point `pixel`.
  Eigen::Vector3d Direction(const Eigen::Vector2d& pixel) const;
  // The unit world direction of a camera-plane point (x, y, 1).
  Eigen::Vector3d DirectionOfCamPlane(const Eigen::Vector2d& xy) const {
    return (world_from_camera_ * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
  }

 private:
  const Camera& camera_;
  Eigen::Matrix3d world_from_camera_;  // rotation
  Eigen::Vector3d eye_;
};

// The camera-plane points of every sub-pixel of a camera: supersample x supersample per pixel, at
// (x + (sx + 0.5) / supersample, y + (sy + 0.5) / supersample). Undistorting is the costly part of a ray
// (a Newton solve); the table does it once per camera instead of once per photo.
class PixelRays {
 public:
  PixelRays(const Camera& camera, int supersample);

  int width() const { return width_; }
  int height() const { return height_; }
  int supersample() const { return supersample_; }
  // Sub-pixel (sx, sy) of pixel (x, y) on the camera plane (z = 1).
  const Eigen::Vector2d& CamPlane(int x, int y, int sx, int sy) const {
    return xy_[((size_t(y) * width_ + x) * supersample_ + sy) * supersample_ + sx];
  }
  // Whether (sx, sy) is the pixel's centre ray (the one masks are decided on).
  bool IsCentre(int sx, int sy) const { return sx == supersample_ / 2 && sy == supersample_ / 2; }

 private:
  int width_ = 0, height_ = 0, supersample_ = 1;
  std::vector<Eigen::Vector2d> xy_;
};

// One ray of RenderRays: its unit world direction, the pixel it belongs to (row-major index) and
// whether it is the pixel's centre ray.
struct PixelRay {
  Eigen::Vector3d direction;
  size_t pixel = 0;
  bool centre = false;
};

// A 3-channel radiance image from `camera_from_world`: each pixel the mean over its sub-pixel rays of
// shade(eye, ray) (an Eigen::Vector3d radiance; 0 for a ray that sees nothing). Rows run in parallel;
// `shade` must be safe to call from several threads (write only to its pixel's entries).
template <typename Shade>
Image RenderRays(const PixelRays& rays, const Rigid3d& camera_from_world, const Shade& shade) {
  const Rigid3d world_from_camera = camera_from_world.Inverse();
  const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d eye = world_from_camera.translation;
  const int w = rays.width(), n = rays.supersample();
  const double weight = 1.0 / (n * n);
  Image image(w, rays.height(), 3);
  tbb::parallel_for(tbb::blocked_range<int>(0, rays.height()), [&](const tbb::blocked_range<int>& rows) {
    PixelRay ray;
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < w; ++x) {
        ray.pixel = size_t(y) * w + x;
        Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
        for (int sy = 0; sy < n; ++sy) {
          for (int sx = 0; sx < n; ++sx) {
            const Eigen::Vector2d& xy = rays.CamPlane(x, y, sx, sy);
            ray.direction = (rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
            ray.centre = rays.IsCentre(sx, sy);
            radiance += shade(eye, ray);
          }
        }
        float* out = &image.pixels[ray.pixel * 3];
        for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(weight * radiance[c]);
      }
    }
  });
  return image;
}

}  // namespace ibrdf
