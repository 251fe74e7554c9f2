#include "report/sphere_render.h"

#include <cmath>

#include <Eigen/Geometry>

namespace ibrdf {

Image RenderSphere(int size, double phase, const BrdfEvalFunction& eval) {
  Image image(size, size, 3);
  const Eigen::Vector3d view(0, 0, 1), light(-std::sin(phase), 0.0, std::cos(phase));  // light from the left
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double u = 2.0 * (x + 0.5) / size - 1.0, v = 1.0 - 2.0 * (y + 0.5) / size;
      const double r2 = u * u + v * v;
      if (r2 >= 1.0) continue;  // background stays black
      const Eigen::Vector3d n(u, v, std::sqrt(1.0 - r2));
      const double cos_i = n.dot(light);
      if (cos_i <= 0.0) continue;
      const Eigen::Matrix3d local_from_world =
          Eigen::Quaterniond::FromTwoVectors(n, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const Eigen::Vector3d f = eval(local_from_world * light, local_from_world * view);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = f[c] < 0.0 ? NAN : float(f[c] * cos_i);
    }
  }
  return image;
}

}  // namespace ibrdf
