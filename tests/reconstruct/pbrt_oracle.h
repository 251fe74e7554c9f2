// pbrt-v4 itself (IBRDF_ORACLES_DIR/pbrt-v4/bin/pbrt: a CPU build of mmp/pbrt-v4 at commit 5f7a606,
// ../shared/oracles/pbrt-v4/README.md) rendering a named material on a lit sphere, and the rendered
// pixels against a BRDF evaluated by ibrdf: for the tests that check ibrdf's pbrt-v4 exports with the
// renderer's own code instead of a re-implementation of it.
//
// The scene: a unit sphere at the origin, an orthographic camera on +z looking down -z (screen window
// [-1.05, 1.05]^2), a distant light of radiance scale pi from the unit direction `light`, one bounce
// ("path", maxdepth 1), a one-pixel box filter, the zsobol sampler (the build's pmj02 tables are not
// pbrt's own), float EXR in linear sRGB. pbrt's LookAt camera is left-handed: the pixel at screen
// position (s_x, s_y) (s_x rightwards, s_y upwards) sees the sphere point (-s_x, s_y, sqrt(1 - s^2))
// (checked on a Lambertian sphere lit from +x: its lit side is on the image's left). There the
// normal is that point, the camera direction +z and the light `light`, and the expected pixel is the
// pixel's mean of f(w_light, w_camera) cos(theta_light) pi in the normal's frame.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/image_io.h"
#include "core/statistics.h"
#include "tests/run_ibrdf.h"

namespace ibrdf::testing {

// The pbrt binary, or "" with `why` saying what is missing.
inline std::string PbrtOracle(std::string* why) {
  const std::string pbrt = std::string(IBRDF_ORACLES_DIR) + "/pbrt-v4/bin/pbrt";
  if (!std::filesystem::exists(pbrt)) {
    *why = pbrt + " does not exist (the test oracles are in ../shared/oracles; CMake's IBRDF_ORACLES_DIR names them)";
    return "";
  }
  const RunResult help = RunShell(pbrt + " --help > /dev/null 2>&1");
  if (help.exit_code != 0) {
    *why = pbrt + " --help exits " + std::to_string(help.exit_code) + " (missing shared libraries? run ldd on it)";
    return "";
  }
  return pbrt;
}

struct SphereRender {
  Image image;  // linear sRGB
  Eigen::Vector3d light = Eigen::Vector3d::UnitZ();
  int resolution = 0;
};

// Renders the material `name` defined by `material_text` (pbrt-v4 scene text with MakeNamedMaterial,
// written to DIR/material.pbrt; files it names are taken from DIR). Fails the test (empty image) when
// pbrt fails.
inline SphereRender RenderSphere(const std::string& pbrt, const std::string& dir, const std::string& material_text,
                                 const std::string& name, const Eigen::Vector3d& light, int resolution, int spp) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/material.pbrt") << material_text;
  std::ofstream scene(dir + "/scene.pbrt");
  scene << "LookAt 0 0 5  0 0 0  0 1 0\n"
        << "Camera \"orthographic\" \"float screenwindow\" [ -1.05 1.05 -1.05 1.05 ]\n"
        << "Film \"rgb\" \"integer xresolution\" [ " << resolution << " ] \"integer yresolution\" [ " << resolution
        << " ] \"string filename\" \"out.exr\" \"bool savefp16\" false\n"
        << "PixelFilter \"box\" \"float xradius\" [ 0.5 ] \"float yradius\" [ 0.5 ]\n"
        << "Sampler \"zsobol\" \"integer pixelsamples\" [ " << spp << " ]\n"
        << "Integrator \"path\" \"integer maxdepth\" [ 1 ]\n"
        << "WorldBegin\n"
        << "LightSource \"distant\" \"point3 from\" [ " << light.x() << " " << light.y() << " " << light.z()
        << " ] \"point3 to\" [ 0 0 0 ] \"float scale\" [ 3.14159265358979 ]\n"
        << "AttributeBegin\n"
        << "  Include \"material.pbrt\"\n"
        << "  NamedMaterial \"" << name << "\"\n"
        << "  Shape \"sphere\" \"float radius\" [ 1 ]\n"
        << "AttributeEnd\n";
  scene.close();
  SphereRender render;
  render.light = light.normalized();
  render.resolution = resolution;
  const RunResult run = RunShell("cd '" + dir + "' && " + pbrt + " --nthreads 2 --quiet scene.pbrt 2>&1");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  if (run.exit_code == 0) render.image = ReadImage(dir + "/out.exr");
  return render;
}

using LocalBrdf = std::function<Eigen::Vector3d(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo)>;

// The rendered pixels against `brdf` (f(wi towards the light, wo towards the camera), local frame)
// over the lit pixels whose centre has theta_light and theta_camera <= max_theta_deg: per channel,
// |rendered - expected| / expected, its median and 95th percentile over every channel of every pixel,
// and the colour ratio (sum rendered / sum expected per channel).
struct PixelComparison {
  size_t pixels = 0;
  double median = 0.0, p95 = 0.0;
  Eigen::Vector3d channel_median = Eigen::Vector3d::Zero();
  Eigen::Vector3d colour_ratio = Eigen::Vector3d::Zero();
  // The same after dividing each channel by its colour ratio: the shape over the sphere alone.
  double shape_median = 0.0, shape_p95 = 0.0;
};

inline PixelComparison CompareWithBrdf(const SphereRender& render, const LocalBrdf& brdf, const std::string& label,
                                       double max_theta_deg = 70.0) {
  PixelComparison result;
  if (render.image.width != render.resolution) return result;
  const int kSub = std::max(4, 192 / render.resolution);  // sub-pixel positions per side for the pixel's mean
  const double pixel = 2.1 / render.resolution, cos_max = std::cos(max_theta_deg * M_PI / 180.0);
  const Eigen::Vector3d camera = Eigen::Vector3d::UnitZ();
  // The expected radiance at screen position (sx, sy), 0 off the sphere or where the light is behind.
  const auto expected_at = [&](double sx, double sy) -> Eigen::Vector3d {
    const double r2 = sx * sx + sy * sy;
    if (r2 >= 1.0) return Eigen::Vector3d::Zero();
    const Eigen::Vector3d n(-sx, sy, std::sqrt(1.0 - r2));
    const Eigen::Vector3d t = (std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY())
                                  .cross(n)
                                  .normalized();
    const Eigen::Vector3d b = n.cross(t);
    const auto local = [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(v.dot(t), v.dot(b), v.dot(n)); };
    const double cos_i = n.dot(render.light);
    if (cos_i <= 0.0) return Eigen::Vector3d::Zero();
    return brdf(local(render.light), local(camera)) * cos_i * M_PI;
  };
  std::vector<double> errors;
  std::vector<double> channel_errors[3];
  std::vector<Eigen::Vector3d> rendered_values, expected_values;
  Eigen::Vector3d rendered_sum = Eigen::Vector3d::Zero(), expected_sum = Eigen::Vector3d::Zero();
  for (int y = 0; y < render.resolution; ++y) {
    for (int x = 0; x < render.resolution; ++x) {
      const double sx = -1.05 + (x + 0.5) * pixel, sy = 1.05 - (y + 0.5) * pixel;
      const double r2 = sx * sx + sy * sy;
      if (r2 >= 1.0) continue;
      const Eigen::Vector3d n(-sx, sy, std::sqrt(1.0 - r2));
      if (n.z() < cos_max || n.dot(render.light) < cos_max) continue;
      Eigen::Vector3d expected = Eigen::Vector3d::Zero();
      for (int j = 0; j < kSub; ++j) {
        for (int i = 0; i < kSub; ++i) {
          expected += expected_at(sx + ((i + 0.5) / kSub - 0.5) * pixel, sy - ((j + 0.5) / kSub - 0.5) * pixel) /
                      double(kSub * kSub);
        }
      }
      if (!(expected.minCoeff() > 0.0)) continue;
      const Eigen::Vector3d rendered(render.image.at(x, y, 0), render.image.at(x, y, 1), render.image.at(x, y, 2));
      rendered_values.push_back(rendered);
      expected_values.push_back(expected);
      rendered_sum += rendered;
      expected_sum += expected;
      for (int c = 0; c < 3; ++c) {
        const double e = std::abs(rendered[c] - expected[c]) / expected[c];
        errors.push_back(e);
        channel_errors[c].push_back(e);
      }
    }
  }
  result.pixels = rendered_values.size();
  if (errors.empty()) return result;
  result.median = Median(errors);
  result.p95 = Percentile(errors, 0.95);
  for (int c = 0; c < 3; ++c) result.channel_median[c] = Median(channel_errors[c]);
  result.colour_ratio = rendered_sum.cwiseQuotient(expected_sum);
  std::vector<double> shape;
  for (size_t k = 0; k < rendered_values.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      shape.push_back(std::abs(rendered_values[k][c] / result.colour_ratio[c] - expected_values[k][c]) /
                      expected_values[k][c]);
    }
  }
  result.shape_median = Median(shape);
  result.shape_p95 = Percentile(shape, 0.95);
  std::printf("%s: %zu lit pixels (theta <= %.0f deg): median %.2f %% (R %.2f, G %.2f, B %.2f), p95 %.2f %%, "
              "colour ratio %.4f / %.4f / %.4f; per-channel-scaled median %.2f %%, p95 %.2f %%\n",
              label.c_str(), result.pixels, max_theta_deg, 100 * result.median, 100 * result.channel_median[0],
              100 * result.channel_median[1], 100 * result.channel_median[2], 100 * result.p95,
              result.colour_ratio[0], result.colour_ratio[1], result.colour_ratio[2], 100 * result.shape_median,
              100 * result.shape_p95);
  return result;
}

}  // namespace ibrdf::testing
