// The report's sphere (report/sphere_render.h): a Lambertian sphere shows albedo/pi times cos(theta_i)
// of the light at the given phase angle, the background and the unlit side stay black, and "no value"
// is NaN.
#include "report/sphere_render.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"

namespace ibrdf {
namespace {

TEST(SphereRender, LambertianShowsCosineOverPi) {
  const int size = 64;
  const double phase = 0.5;
  const Image image = RenderSphere(size, phase, [](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
    EXPECT_NEAR(wi.norm(), 1.0, 1e-12);
    EXPECT_GT(wo.z(), 0.0);
    return Eigen::Vector3d(Eigen::Vector3d::Constant(0.5 / kPi));
  });
  const Eigen::Vector3d light(-std::sin(phase), 0.0, std::cos(phase));
  int lit = 0;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double u = 2.0 * (x + 0.5) / size - 1.0, v = 1.0 - 2.0 * (y + 0.5) / size;
      const double r2 = u * u + v * v;
      const double cos_i = r2 < 1.0 ? Eigen::Vector3d(u, v, std::sqrt(1.0 - r2)).dot(light) : 0.0;
      const double expected = cos_i > 0.0 ? 0.5 / kPi * cos_i : 0.0;
      EXPECT_NEAR(image.at(x, y, 1), expected, 1e-6) << x << ", " << y;
      lit += expected > 0.0;
    }
  }
  EXPECT_GT(lit, size * size / 2);
  EXPECT_EQ(image.at(0, 0, 0), 0.0f);  // a corner: background
}

TEST(SphereRender, NoValueIsNan) {
  const Image image = RenderSphere(
      16, 0.0, [](const Eigen::Vector3d&, const Eigen::Vector3d&) { return Eigen::Vector3d(-1.0, 0.1, 0.1); });
  EXPECT_TRUE(std::isnan(image.at(8, 8, 0)));
  EXPECT_GT(image.at(8, 8, 1), 0.0f);
}

}  // namespace
}  // namespace ibrdf
