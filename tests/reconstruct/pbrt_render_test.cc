// Every pbrt-v4 export ibrdf writes, rendered by pbrt-v4 itself (tests/reconstruct/pbrt_oracle.h: a
// unit sphere, orthographic camera, a distant light 45 degrees from it) and compared pixel by pixel
// with ibrdf's own evaluation of the same BRDF over the lit pixels with theta_light, theta_camera <= 70
// degrees: the NAME.pbrt snippet of a GGX fit (a `mix` of a diffuse and a conductor; a `conductor` for
// a metal) against the fit, and the `measured` material reading NAME.bsdf against core/rgl_bsdf.h's
// evaluation of the file. Skips with a message where the pbrt binary is absent or does not run.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/rgl_bsdf.h"
#include "core/tensor_file.h"
#include "reconstruct/bsdf_export.h"
#include "reconstruct/model_fit.h"
#include "tests/reconstruct/pbrt_oracle.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::CompareWithBrdf;
using testing::PixelComparison;
using testing::RenderSphere;
using testing::ScratchDir;

// 48 x 48 pixels (about 1000 lit ones with theta <= 70 degrees) at 64 samples each: pbrt's spectral
// sampling leaves 0.1-0.2 % median noise on a single material.
constexpr int kResolution = 48;
constexpr int kSpp = 64;
const Eigen::Vector3d kLight(std::sin(M_PI / 4), 0.0, std::cos(M_PI / 4));

ModelFitResult GgxFit(const Eigen::Vector3d& diffuse, const Eigen::Vector3d& f0, double alpha, GgxFresnel fresnel) {
  ModelFitResult fit;
  fit.success = true;
  fit.model = "ggx";
  fit.brdf = std::make_unique<GgxBrdf>(diffuse, f0, alpha, fresnel);
  return fit;
}

// The snippets of a light paint (a mix) and of a copper-like metal (a conductor), against the GGX BRDF
// they were written from. Bound: median 1 %, 95th percentile 5 % (tested). A mix renders one of its
// two materials per shading point (chosen by a hash of the point and the direction), so its pixels
// carry that choice's noise, relative standard deviation sqrt(amount / (1 - amount)) per sample where
// the diffuse dominates: 1.1 for a dark paint (amount 0.55), 0.42 for this one (amount 0.15). It is
// rendered at 16 x 16 pixels (about 110 lit ones) with 4096 samples each (about 3 s).
TEST(PbrtRender, SnippetsRenderTheirFit) {
  std::string why;
  const std::string pbrt = testing::PbrtOracle(&why);
  if (pbrt.empty()) GTEST_SKIP() << "pbrt-v4 oracle absent: " << why;
  ScratchDir dir;
  struct Case {
    std::string label, kind;
    ModelFitResult fit;
    int resolution, spp;
  };
  Case cases[] = {
      {"paint (mix)", "mix",
       GgxFit(Eigen::Vector3d(0.85, 0.75, 0.6), Eigen::Vector3d::Constant(0.04), 0.2, GgxFresnel::kDielectric), 16,
       4096},
      {"copper-like (conductor)", "conductor",
       GgxFit(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25, GgxFresnel::kSchlick), kResolution,
       kSpp},
  };
  for (Case& c : cases) {
    const RendererSnippets snippets = RendererMaterials(c.fit, "m", "linear sRGB (D65)");
    ASSERT_EQ(snippets.kind, c.kind) << snippets.pbrt;
    const auto render = RenderSphere(pbrt, dir / c.kind, snippets.pbrt, "m", kLight, c.resolution, c.spp);
    const PixelComparison p = CompareWithBrdf(
        render, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return c.fit.brdf->Eval(wi, wo); },
        "pbrt-v4 " + c.label + " against the fit");
    EXPECT_GT(p.pixels, c.resolution * c.resolution / 3u) << c.label;
    EXPECT_LT(p.median, 0.01) << c.label << "\n" << snippets.pbrt;
    EXPECT_LT(p.p95, 0.05) << c.label << "\n" << snippets.pbrt;
  }
}

TensorFile ExportOf(const BrdfModel& model) {
  const BrdfBatch batch = [&model](const std::vector<Eigen::Vector3d>& wi, const std::vector<Eigen::Vector3d>& wo,
                                   std::vector<Eigen::Vector3d>* f) {
    f->resize(wi.size());
    for (size_t i = 0; i < wi.size(); ++i) (*f)[i] = model.Eval(wi[i], wo[i]);
  };
  return BuildRglBsdf(batch, "pbrt_render_test", BsdfExportOptions{});
}

// pbrt-v4's `measured` material reading the .bsdf ibrdf writes, against ibrdf's reading of the same
// file. A grey file (equal channels: its box spectrum is flat) within median 1 %, 95th percentile 5 %
// (tested): pbrt reads the file's geometry and warps as ibrdf does. A coloured one (bluepaint) renders
// off in colour, because pbrt interpolates the box spectrum linearly in wavelength (said, not bounded
// here); its shape over the sphere, each channel scaled by its colour ratio, within the same bounds
// (tested).
TEST(PbrtRender, MeasuredMaterialRendersTheBsdf) {
  std::string why;
  const std::string pbrt = testing::PbrtOracle(&why);
  if (pbrt.empty()) GTEST_SKIP() << "pbrt-v4 oracle absent: " << why;
  ScratchDir dir;
  const GgxBrdf grey(Eigen::Vector3d::Constant(0.2), Eigen::Vector3d::Constant(0.04), 0.3, GgxFresnel::kDielectric);
  const auto bluepaint = LoadMaterial(testing::MaterialPath("bluepaint"));
  struct Case {
    std::string label;
    const BrdfModel* model;
    bool grey;
  };
  for (const Case& c : {Case{"grey GGX", &grey, true}, Case{"bluepaint", bluepaint.get(), false}}) {
    const std::string folder = dir / (c.grey ? "grey" : "colour");
    std::filesystem::create_directories(folder);
    WriteTensorFile(folder + "/m.bsdf", ExportOf(*c.model));
    const RglBsdf file(folder + "/m.bsdf");
    const auto render = RenderSphere(
        pbrt, folder, "MakeNamedMaterial \"m\" \"string type\" \"measured\" \"string filename\" \"m.bsdf\"\n", "m",
        kLight, kResolution, kSpp);
    const PixelComparison p = CompareWithBrdf(
        render, [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) { return file.Eval(wi, wo); },
        "pbrt-v4 measured, " + c.label + " .bsdf, against ibrdf's reading of it");
    EXPECT_GT(p.pixels, 500u) << c.label;
    EXPECT_LT(p.shape_median, 0.01) << c.label;
    EXPECT_LT(p.shape_p95, 0.05) << c.label;
    if (c.grey) {
      EXPECT_LT(p.median, 0.01) << c.label;
      EXPECT_LT(p.p95, 0.05) << c.label;
    }
  }
}

}  // namespace
}  // namespace ibrdf
