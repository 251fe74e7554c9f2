// The materials stage's pbrt-v4 scene (spatial/material_scene.h) rendered by pbrt-v4 itself
// (tests/reconstruct/pbrt_oracle.h) and held against ibrdf's own render of the same model, pixel by
// pixel: the squash of samples/squash-materials (three materials in stripes and blends, scanned mesh,
// markers) through `ibrdf run --spatial`, then `pbrt` on materials/pbrt/photo-N.pbrt. pbrt's camera,
// light, mesh parts, mixes and the groups' exported materials must together reproduce ibrdf's
// radiance (the cells' two largest weights scaled to the cell's sum of weights, as the scene's mixes
// with black under its scaled light have them, over the groups' GGX fits, times cos theta_i / r^2) within 2 % median
// over 7 x 7-pixel windows; per pixel pbrt's stochastic mixes leave noise even at 2048 samples per pixel, and the
// scene's weights are per face and in 0.1 steps (both reported, docs/spatial.md). The Mitsuba 3 scene of the same run
// is checked for its parts and materials. Skips the render with a message where the pbrt binary is absent or does not
// run.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/statistics.h"
#include "tests/reconstruct/pbrt_oracle.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::RunIbrdf;
using testing::RunResult;
using testing::RunShell;
using testing::ScratchDir;

TEST(MaterialScenePbrt, RendersTheSpatiallyVaryingSquashAsIbrdfDoes) {
  ScratchDir dir;
  // The recipe at 8 photos (the squash's 16 cost twice the derender; 6 photos measure too,
  // docs/spatial.md's hard cases).
  const std::string samples = IBRDF_SAMPLES_DIR;
  fs::create_directories(dir / "squash");
  WriteJsonFile(dir / "squash/recipe.json",
                {{"format", "ibrdf-recipe"},
                 {"version", 1},
                 {"name", "squash-materials-8"},
                 {"material_map", samples + "/squash-materials/material-map.json"},
                 {"synth", {"--shape", "squash", "--targets", "--seed", "5", "--photos", "8"}}});
  const auto run = RunIbrdf("run " + (dir / "squash") + " --out " + (dir / "r") + " --spatial --no-report",
                            /*quiet=*/true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json materials = ReadJsonFile(dir / "r/materials/materials.json");
  const nlohmann::json& scene = materials.at("pbrt");
  ASSERT_TRUE(scene.at("written").get<bool>()) << scene.dump(2);
  ASSERT_TRUE(scene.at("ibrdf_image").is_string()) << scene.dump(2);
  // The two largest weights carry nearly all of the model: every weight renders within 2 % as bright.
  EXPECT_NEAR(scene.at("weight_sums").at("full_weights_brightness_ratio").get<double>(), 1.0, 0.02) << scene.dump(2);
  EXPECT_GE(scene.at("light_scale").get<double>(), 1.0);
  // The Mitsuba 3 scene beside it: every group's material inlined and every part of the pbrt scene.
  ASSERT_TRUE(scene.at("mitsuba_scene").is_string()) << scene.dump(2);
  std::ifstream xml_file(dir / ("r/materials/" + scene.at("mitsuba_scene").get<std::string>()));
  const std::string xml((std::istreambuf_iterator<char>(xml_file)), std::istreambuf_iterator<char>());
  for (const nlohmann::json& group : materials.at("groups")) {
    if (!group.value("reconstructed", false)) continue;
    EXPECT_NE(xml.find("id=\"squash-materials-8-" + group.at("folder").get<std::string>() + "\""), std::string::npos)
        << group.dump();
  }
  for (const auto& entry : fs::directory_iterator(dir / "r/materials/pbrt")) {
    if (entry.path().extension() != ".ply") continue;
    EXPECT_NE(xml.find("value=\"../pbrt/" + entry.path().filename().string() + "\""), std::string::npos)
        << entry.path();
  }

  std::string why;
  const std::string pbrt = testing::PbrtOracle(&why);
  if (pbrt.empty()) GTEST_SKIP() << "pbrt-v4 oracle not available (the scenes were checked, not rendered): " << why;
  const fs::path folder = fs::path(dir / "r/materials") / fs::path(scene.at("scene").get<std::string>()).parent_path();
  const std::string file = fs::path(scene.at("scene").get<std::string>()).filename().string();
  const Image by_ibrdf = ReadImage((folder / scene.at("ibrdf_image").get<std::string>()).string());
  ASSERT_EQ(by_ibrdf.channels, 4);
  // pbrt renders the rendered pixels' bounding box only, at 2048 samples per pixel: its mixes pick one
  // material per sample, and at the scene's 64 their noise is 13 % per pixel here.
  int x0 = by_ibrdf.width, y0 = by_ibrdf.height, x1 = 0, y1 = 0;
  size_t pixels = 0;
  for (int y = 0; y < by_ibrdf.height; ++y) {
    for (int x = 0; x < by_ibrdf.width; ++x) {
      if (by_ibrdf.at(x, y, 3) != 1.0f) continue;
      ++pixels;
      x0 = std::min(x0, x);
      y0 = std::min(y0, y);
      x1 = std::max(x1, x + 1);
      y1 = std::max(y1, y + 1);
    }
  }
  ASSERT_EQ(pixels, scene.at("ibrdf_pixels").get<size_t>());
  ASSERT_GT(pixels, 3000u) << "too few rendered pixels to judge";
  const RunResult rendered =
      RunShell("cd '" + folder.string() + "' && " + pbrt + " --nthreads 2 --quiet --spp 2048 --pixelbounds " +
               std::to_string(x0) + "," + std::to_string(x1) + "," + std::to_string(y0) + "," + std::to_string(y1) +
               " " + file + " 2>&1");
  ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
  // The EXR holds the bounds (its data window); ReadImage returns that window.
  const Image by_pbrt = ReadImage((folder / scene.at("image").get<std::string>()).string());
  ASSERT_EQ(by_pbrt.width, x1 - x0);
  ASSERT_EQ(by_pbrt.height, y1 - y0);
  ASSERT_GE(by_pbrt.channels, 3);
  const auto rendered_at = [&](int x, int y) { return by_ibrdf.at(x, y, 3) == 1.0f; };

  // |pbrt / ibrdf - 1| per channel: per pixel, and over each rendered pixel's 7 x 7 window (the sums of
  // its rendered pixels, where they are at least half the window), which averages pbrt's noise.
  std::vector<double> per_pixel, per_window;
  Eigen::Vector3d sum_pbrt = Eigen::Vector3d::Zero(), sum_ibrdf = Eigen::Vector3d::Zero();
  size_t black = 0;
  constexpr int kHalf = 3;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      if (!rendered_at(x, y)) continue;
      bool dark = true;
      for (int c = 0; c < 3; ++c) {
        const double expected = by_ibrdf.at(x, y, c), got = by_pbrt.at(x - x0, y - y0, c);
        dark = dark && got == 0.0;
        if (expected > 0.0) per_pixel.push_back(std::abs(got / expected - 1.0));
        sum_pbrt[c] += got;
        sum_ibrdf[c] += expected;
      }
      if (dark) ++black;
      Eigen::Vector3d window_pbrt = Eigen::Vector3d::Zero(), window_ibrdf = Eigen::Vector3d::Zero();
      int n = 0;
      for (int v = std::max(y0, y - kHalf); v <= std::min(y1 - 1, y + kHalf); ++v) {
        for (int u = std::max(x0, x - kHalf); u <= std::min(x1 - 1, x + kHalf); ++u) {
          if (!rendered_at(u, v)) continue;
          ++n;
          for (int c = 0; c < 3; ++c) {
            window_pbrt[c] += by_pbrt.at(u - x0, v - y0, c);
            window_ibrdf[c] += by_ibrdf.at(u, v, c);
          }
        }
      }
      if (2 * n < (2 * kHalf + 1) * (2 * kHalf + 1)) continue;
      for (int c = 0; c < 3; ++c) {
        if (window_ibrdf[c] > 0.0) per_window.push_back(std::abs(window_pbrt[c] / window_ibrdf[c] - 1.0));
      }
    }
  }
  ASSERT_GT(per_window.size(), per_pixel.size() / 2);
  const double pixel_median = Median(per_pixel), window_median = Median(per_window);
  const double window_p90 = Percentile(per_window, 0.90);
  const Eigen::Vector3d ratio = sum_pbrt.cwiseQuotient(sum_ibrdf);
  std::cout << "pbrt-v4 (2048 spp) against ibrdf's render of the scene's model: " << pixels
            << " pixels; median |pbrt / ibrdf - 1| per pixel " << 100.0 * pixel_median << " %, over 7 x 7 windows "
            << 100.0 * window_median << " % (p90 " << 100.0 * window_p90 << " %); colour ratio " << ratio.transpose()
            << "; pixels black in pbrt " << black << "\n";
  EXPECT_LT(window_median, 0.02);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(ratio[c], 1.0, 0.02) << "channel " << c;
  // A camera off by a few pixels, or a light in the wrong place, leaves pixels black that ibrdf lit.
  EXPECT_LT(double(black), 0.005 * double(pixels));
}

}  // namespace
}  // namespace ibrdf
