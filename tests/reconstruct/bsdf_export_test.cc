#include "reconstruct/bsdf_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/rgl_bsdf.h"
#include "core/statistics.h"
#include "core/tensor_file.h"
#include "tests/error_of.h"
#include "tests/reconstruct/mitsuba_measured.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::ErrorOf;
using testing::MaterialPath;
using testing::ScratchDir;

BrdfBatch BatchOf(const BrdfModel& model) {
  return [&model](const std::vector<Eigen::Vector3d>& wi, const std::vector<Eigen::Vector3d>& wo,
                  std::vector<Eigen::Vector3d>* f) {
    f->resize(wi.size());
    for (size_t i = 0; i < wi.size(); ++i) (*f)[i] = model.Eval(wi[i], wo[i]);
  };
}

struct FileError {
  double median = 0.0, p95 = 0.0;
};

// |file - model| / model over every channel on a grid theta_i, theta_o <= max_deg (5-degree steps),
// delta_phi 0 to 180 degrees (15-degree steps).
FileError ErrorOfFile(const RglBsdf& file, const BrdfModel& model, double max_deg) {
  std::vector<double> errors;
  for (double ti = 0.0; ti <= max_deg + 1e-9; ti += 5.0) {
    for (double to = 0.0; to <= max_deg + 1e-9; to += 5.0) {
      for (double dp = 0.0; dp <= 180.0 + 1e-9; dp += 15.0) {
        const Eigen::Vector3d wi = FromSpherical(ti * M_PI / 180, 0.0);
        const Eigen::Vector3d wo = FromSpherical(to * M_PI / 180, dp * M_PI / 180);
        const Eigen::Vector3d f = model.Eval(wi, wo), g = file.Eval(wi, wo);
        for (int c = 0; c < 3; ++c) errors.push_back(std::abs(g[c] - f[c]) / f[c]);
      }
    }
  }
  std::sort(errors.begin(), errors.end());
  return {errors[errors.size() / 2], errors[size_t(0.95 * double(errors.size()))]};
}

std::unique_ptr<RglBsdf> ExportAndRead(const BrdfModel& model, const std::string& path, const std::string& text) {
  WriteTensorFile(path, BuildRglBsdf(BatchOf(model), text, BsdfExportOptions{}));
  return std::make_unique<RglBsdf>(path);
}

TEST(BsdfExport, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(BsdfExportOptions{}.Check(&why)) << why;
  BsdfExportOptions bad;
  bad.max_theta_i_deg = 90.0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_NE(ErrorOf([&] {
              BuildRglBsdf(BatchOf(LambertianBrdf({0.5, 0.5, 0.5})), "", bad);
            }).find("max_theta_i_deg"),
            std::string::npos);
}

// A Lambertian surface must read back as albedo / pi wherever it is evaluated: every table (NDF,
// sigma, the VNDF warp and its inverse, the rgb interpolation) takes part.
TEST(BsdfExport, LambertianReadsBackAsAlbedoOverPi) {
  ScratchDir dir;
  const LambertianBrdf lambert({0.8, 0.4, 0.1});
  const auto file = ExportAndRead(lambert, dir / "lambert.bsdf", "lambertian");
  const FileError e = ErrorOfFile(*file, lambert, 80.0);
  std::printf("lambertian: median %.4f %%, p95 %.4f %%\n", 100 * e.median, 100 * e.p95);
  EXPECT_LT(e.median, 0.005);
  EXPECT_LT(e.p95, 0.01);
  EXPECT_EQ(file->description(), "lambertian");
  EXPECT_TRUE(file->isotropic());
}

// The file holds every field the readers require, with their shapes (brdf-loader's RGB mode, and the
// spectral fields pbrt-v4 and Mitsuba 3 require).
TEST(BsdfExport, FileHasTheFieldsTheReadersRequire) {
  ScratchDir dir;
  const LambertianBrdf lambert({0.5, 0.5, 0.5});
  WriteTensorFile(dir / "l.bsdf", BuildRglBsdf(BatchOf(lambert), "x", BsdfExportOptions{}));
  const TensorFile file = ReadTensorFile(dir / "l.bsdf");
  for (const char* name : {"description", "theta_i", "phi_i", "ndf", "sigma", "vndf", "luminance", "rgb", "spectra",
                           "wavelengths", "jacobian"}) {
    EXPECT_TRUE(file.count(name)) << name;
  }
  EXPECT_EQ(file.at("rgb").Describe(), "float32 [1, 23, 3, 64, 64]");
  EXPECT_EQ(file.at("spectra").Describe(), "float32 [1, 23, 6, 64, 64]");
  EXPECT_EQ(file.at("luminance").Describe(), "float32 [1, 23, 64, 64]");
  EXPECT_EQ(file.at("vndf").Describe(), "float32 [1, 23, 64, 64]");
  EXPECT_EQ(file.at("ndf").Describe(), "float32 [2, 128]");
  EXPECT_EQ(file.at("jacobian").Describe(), "uint8 [1]");
}

// The `jacobian` byte says whether a reader multiplies the table by ndf / (4 sigma); the tables are
// written for that product, so the byte must be 1. brdf-loader, pbrt-v4 and core/rgl_bsdf.h multiply
// whatever the byte says, Mitsuba 3 only when it is set (tests/reconstruct/mitsuba_measured.h follows
// its measured.cpp): read Mitsuba's way the file gives what the others read (at the box spectrum's
// plateaus 700, 530 and 420 nm in a spectral variant, the rgb channels in an RGB one), and the same
// file with the byte 0 does not, while the others cannot tell the two apart.
TEST(BsdfExport, JacobianIsSetAndMitsubaReadsWhatTheOthersRead) {
  ScratchDir dir;
  const GgxBrdf ggx(Eigen::Vector3d(0.3, 0.2, 0.1), Eigen::Vector3d(0.04, 0.04, 0.04), 0.3);
  WriteTensorFile(dir / "set.bsdf", BuildRglBsdf(BatchOf(ggx), "ggx", BsdfExportOptions{}));
  TensorFile file = ReadTensorFile(dir / "set.bsdf");
  ASSERT_EQ(file.at("jacobian").data, std::vector<uint8_t>{1});
  file["jacobian"] = BytesField({0});
  WriteTensorFile(dir / "unset.bsdf", file);
  const bool spectral = file.count("wavelengths") > 0;
  const std::vector<float> lambdas = spectral ? std::vector<float>{700.0f, 530.0f, 420.0f}
                                              : std::vector<float>{0.0f, 1.0f, 2.0f};
  const testing::MitsubaMeasured mitsuba(dir / "set.bsdf", spectral), mitsuba_unset(dir / "unset.bsdf", spectral);
  EXPECT_TRUE(mitsuba.jacobian());
  EXPECT_FALSE(mitsuba_unset.jacobian());
  const RglBsdf others(dir / "set.bsdf"), others_unset(dir / "unset.bsdf");
  std::vector<double> set_error, unset_error;
  for (int ti = 5; ti <= 75; ti += 10) {
    for (int to = 5; to <= 75; to += 10) {
      for (int dp = 0; dp <= 180; dp += 30) {
        const Eigen::Vector3d light = FromSpherical(ti * M_PI / 180, 0.0);
        const Eigen::Vector3d camera = FromSpherical(to * M_PI / 180, dp * M_PI / 180);
        const Eigen::Vector3d g = others.EvalCosine(camera, light);
        EXPECT_EQ(others_unset.EvalCosine(camera, light), g);
        const std::vector<double> m = mitsuba.Eval(camera, light, lambdas),
                                  u = mitsuba_unset.Eval(camera, light, lambdas);
        for (int c = 0; c < 3; ++c) {
          ASSERT_GT(g[c], 0.0);
          set_error.push_back(std::abs(m[c] - g[c]) / g[c]);
          unset_error.push_back(std::abs(u[c] - g[c]) / g[c]);
        }
      }
    }
  }
  const double set_max = *std::max_element(set_error.begin(), set_error.end());
  std::printf("Mitsuba 3's reading against brdf-loader's: max %.2g with the byte set; median %.1f %% with it 0\n",
              set_max, 100 * Median(unset_error));
  EXPECT_LT(set_max, 1e-4);
  EXPECT_GT(Median(unset_error), 0.1);
}

// Glossy materials: the file against the model it was written from, theta <= 80 degrees.
TEST(BsdfExport, GlossyMaterialsReadBackWithinTheStatedError) {
  ScratchDir dir;
  struct Case {
    const char* name;
    std::unique_ptr<BrdfModel> model;
    double median_bound, p95_bound;
  };
  std::vector<Case> cases;
  cases.push_back({"bluepaint", LoadMaterial(MaterialPath("bluepaint")), 0.005, 0.03});
  cases.push_back({"ggx-0.3",
                   std::make_unique<GgxBrdf>(Eigen::Vector3d(0.3, 0.2, 0.1), Eigen::Vector3d(0.04, 0.04, 0.04), 0.3),
                   0.005, 0.03});
  cases.push_back({"copper-0.25",
                   std::make_unique<GgxBrdf>(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25), 0.005,
                   0.03});
  cases.push_back({"ggx-0.1",
                   std::make_unique<GgxBrdf>(Eigen::Vector3d(0.2, 0.2, 0.2), Eigen::Vector3d(0.04, 0.04, 0.04), 0.1),
                   0.005, 0.03});
  for (const Case& c : cases) {
    const auto file = ExportAndRead(*c.model, dir / (std::string(c.name) + ".bsdf"), c.name);
    const FileError e = ErrorOfFile(*file, *c.model, 80.0);
    std::printf("%s: median %.3f %%, p95 %.3f %%\n", c.name, 100 * e.median, 100 * e.p95);
    EXPECT_LT(e.median, c.median_bound) << c.name;
    EXPECT_LT(e.p95, c.p95_bound) << c.name;
  }
}

// LoadMaterial and material files take a .bsdf, so synth, compare and --truth accept one.
TEST(BsdfExport, LoadMaterialReadsBsdfFiles) {
  ScratchDir dir;
  const LambertianBrdf lambert({0.5, 0.25, 0.125});
  WriteTensorFile(dir / "m.bsdf", BuildRglBsdf(BatchOf(lambert), "m", BsdfExportOptions{}));
  const auto model = LoadMaterial(dir / "m.bsdf");
  EXPECT_EQ(model->ModelName(), "rgl_bsdf");
  const Eigen::Vector3d f = model->Eval(FromSpherical(0.3, 0.0), FromSpherical(0.5, 2.0));
  EXPECT_NEAR(f[1], 0.25 / M_PI, 0.01 * 0.25 / M_PI);
  const auto again = MaterialFromJson(model->ToJson(), "");
  EXPECT_EQ(again->ModelName(), "rgl_bsdf");
  EXPECT_NE(ErrorOf([&] { LoadMaterial(dir / "missing.bsdf"); }).find("missing.bsdf"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
