// The .bsdf that `ibrdf reconstruct` writes, read by the format's authors' own reader (rgl-epfl
// brdf-loader, powitacq_rgb.h, compiled from ../shared/oracles; never copied here) and compared with
// ibrdf's table over the measured domain: for every measured cell centre of the MERL table with
// theta_i, theta_e <= 80 degrees, |f_loader - f_table| / f_table per channel, by the larger of the two
// angles (0-25, 25-50, 50-80 degrees), median, 99th percentile and maximum; and the file's
// reciprocity through the same reader, |f(wi, wo) - f(wo, wi)| / (their mean), over the same cells.
// brdf-loader's BRDF::eval(p, q) returns f_r cos(theta_q) with p the table's parameter direction,
// which Mitsuba 3 and pbrt-v4 take as the camera's: f(wi, wo) = eval(wo, wi) / cos(theta_i) (wi
// towards the light, wo towards the camera, docs/conventions.md). Two sessions through the CLI: the
// demo's (samples/bluepaint-sphere: bluepaint on a sphere, 20 photos on the arc from 8 to 172 degrees)
// and one with every light within 45 degrees of the camera (the arc from 8 to 45 degrees).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/brdf_coords.h"
#include "core/merl_format.h"
#include "core/npy.h"
#include "core/rgl_bsdf.h"
#include "core/tensor_file.h"
#include "tests/reconstruct/mitsuba_measured.h"
#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

#ifdef IBRDF_BRDF_LOADER_DIR
#define POWITACQ_IMPLEMENTATION 1
#include "powitacq_rgb.h"
#endif

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::ScratchDir;

// A reconstruct run's outputs: the .bsdf, the MERL table and its domain.
struct Reconstruction {
  std::string bsdf, table, domain;
};

// synth (bluepaint, a sphere, seed 1, `synth_options`), derender and reconstruct with their defaults.
Reconstruction RunSession(const ScratchDir& dir, const std::string& synth_options) {
  const std::string session = dir / "s", samples = dir / "s.npy", out = dir / "rec";
  const auto synth = RunIbrdf("synth --out " + session + " --material " + testing::MaterialPath("bluepaint") +
                              " --sample sphere --seed 1 " + synth_options);
  EXPECT_EQ(synth.exit_code, 0) << synth.output;
  const auto derender = RunIbrdf("derender " + session + " --out " + samples);
  EXPECT_EQ(derender.exit_code, 0) << derender.output;
  const auto reconstruct = RunIbrdf("reconstruct " + samples + " --out " + out);
  EXPECT_EQ(reconstruct.exit_code, 0) << reconstruct.output;
  Reconstruction r{"", out + "/brdf.binary", out + "/domain.npy"};
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    if (entry.path().extension() == ".bsdf") r.bsdf = entry.path().string();
  }
  EXPECT_FALSE(r.bsdf.empty()) << "no .bsdf in " << out;
  return r;
}

// The file's `jacobian` byte is 1, and Mitsuba 3's reading of it (it honours the byte;
// tests/reconstruct/mitsuba_measured.h) is brdf-loader's: at the box spectrum's plateaus (700, 530 and
// 420 nm: red, green, blue) in a spectral variant, or the rgb channels in an RGB one, on a grid of
// directions (max relative difference under 1e-4).
void ExpectMitsubaReadsTheFileAsTheOthers(const std::string& path) {
  const TensorFile file = ReadTensorFile(path);
  ASSERT_TRUE(file.count("jacobian")) << path;
  EXPECT_EQ(file.at("jacobian").data, std::vector<uint8_t>{1}) << path;
  const bool spectral = file.count("wavelengths") > 0;
  const testing::MitsubaMeasured mitsuba(path, spectral);
  const std::vector<float> lambdas = spectral ? std::vector<float>{700.0f, 530.0f, 420.0f}
                                              : std::vector<float>{0.0f, 1.0f, 2.0f};
  const RglBsdf ibrdf(path);
  double worst = 0.0;
  for (int ti = 5; ti <= 75; ti += 10) {
    for (int to = 5; to <= 75; to += 10) {
      for (int dp = 0; dp <= 180; dp += 30) {
        const Eigen::Vector3d light = FromSpherical(ti * M_PI / 180, 0.0);
        const Eigen::Vector3d camera = FromSpherical(to * M_PI / 180, dp * M_PI / 180);
        const std::vector<double> m = mitsuba.Eval(camera, light, lambdas);
        const Eigen::Vector3d g = ibrdf.EvalCosine(camera, light);
        for (int c = 0; c < 3; ++c) {
          if (g[c] > 0.0) worst = std::max(worst, std::abs(m[c] - g[c]) / g[c]);
        }
      }
    }
  }
  std::printf("Mitsuba 3's reading (%s variant) against ibrdf's: max relative difference %.2g\n",
              spectral ? "spectral" : "RGB", worst);
  EXPECT_LT(worst, 1e-4) << path;
}

#ifdef IBRDF_BRDF_LOADER_DIR

struct Quantiles {
  double median = 0.0, p99 = 0.0, max = 0.0;
  size_t count = 0;
};
Quantiles QuantilesOf(std::vector<double> values) {
  Quantiles q;
  q.count = values.size();
  if (values.empty()) return q;
  std::sort(values.begin(), values.end());
  const auto at = [&](double p) { return values[std::min(values.size() - 1, size_t(p * double(values.size())))]; };
  q.median = at(0.5);
  q.p99 = at(0.99);
  q.max = values.back();
  return q;
}

struct OracleFigures {
  Quantiles bands[3], all;               // brdf-loader against the table
  Quantiles reciprocity_bands[3], reciprocity;
  double reader_difference = 0.0;        // brdf-loader against core/rgl_bsdf.h, max relative
  // The worst cell against the table (degrees) and its ratio file / table.
  double worst_theta_i = 0.0, worst_theta_o = 0.0, worst_phi = 0.0, worst_ratio = 1.0;
};

// theta (degrees) of a unit vector of the local frame.
double ThetaDeg(const Eigen::Vector3d& w) { return std::acos(std::clamp(w.z(), -1.0, 1.0)) * 180.0 / M_PI; }

OracleFigures CompareThroughBrdfLoader(const Reconstruction& r) {
  const powitacq_rgb::BRDF loader(r.bsdf);
  const RglBsdf ibrdf(r.bsdf);
  const MerlTable table = ReadMerl(r.table);
  std::vector<size_t> shape;
  const std::vector<uint8_t> domain = ReadNpy<uint8_t>(r.domain, "'|u1'", &shape);
  EXPECT_EQ(domain.size(), kMerlCells);
  // f(wi, wo) through brdf-loader, the camera (wo) as the parameter direction.
  const auto f = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) -> Eigen::Vector3d {
    const powitacq_rgb::Vector3f v =
        loader.eval(powitacq_rgb::Vector3f(float(wo.x()), float(wo.y()), float(wo.z())),
                    powitacq_rgb::Vector3f(float(wi.x()), float(wi.y()), float(wi.z())));
    return Eigen::Vector3d(v[0], v[1], v[2]) / wi.z();
  };
  std::vector<double> bands[3], all, reciprocity_bands[3], reciprocity;
  OracleFigures figures;
  double worst = -1.0;
  for (size_t flat = 0; flat < domain.size(); ++flat) {
    if (domain[flat] != 2) continue;  // measured
    const int i_h = int(flat / (size_t(kMerlThetaD) * kMerlPhiD)), i_d = int(flat / kMerlPhiD % kMerlThetaD),
              i_p = int(flat % kMerlPhiD);
    Eigen::Vector3d wi, wo;
    FromHalfDiff(MerlCellCentre(i_h, i_d, i_p), &wi, &wo);
    const double theta_max = std::max(ThetaDeg(wi), ThetaDeg(wo));
    if (theta_max > 80.0) continue;
    const int band = theta_max < 25.0 ? 0 : theta_max < 50.0 ? 1 : 2;
    const Eigen::Vector3d t = table.Cell(flat), g = f(wi, wo), swapped = f(wo, wi), own = ibrdf.Eval(wi, wo);
    for (int c = 0; c < 3; ++c) {
      if (!(t[c] > 0.0)) continue;
      const double e = std::abs(g[c] - t[c]) / t[c];
      all.push_back(e);
      bands[band].push_back(e);
      if (e > worst) {
        worst = e;
        figures.worst_theta_i = ThetaDeg(wi);
        figures.worst_theta_o = ThetaDeg(wo);
        figures.worst_phi = std::abs(std::remainder(std::atan2(wo.y(), wo.x()) - std::atan2(wi.y(), wi.x()),
                                                    2.0 * M_PI)) * 180.0 / M_PI;
        figures.worst_ratio = g[c] / t[c];
      }
      if (g[c] + swapped[c] > 0.0) {
        const double rec = 2.0 * std::abs(g[c] - swapped[c]) / (g[c] + swapped[c]);
        reciprocity.push_back(rec);
        reciprocity_bands[band].push_back(rec);
      }
      if (g[c] > 0.0) figures.reader_difference = std::max(figures.reader_difference, std::abs(own[c] - g[c]) / g[c]);
    }
  }
  figures.all = QuantilesOf(all);
  figures.reciprocity = QuantilesOf(reciprocity);
  for (int b = 0; b < 3; ++b) {
    figures.bands[b] = QuantilesOf(bands[b]);
    figures.reciprocity_bands[b] = QuantilesOf(reciprocity_bands[b]);
  }
  return figures;
}

void Print(const std::string& label, const OracleFigures& o) {
  const char* names[] = {"0-25", "25-50", "50-80"};
  std::printf("%s: brdf-loader against the table over %zu measured values: median %.3f %%, p99 %.2f %%, max %.1f %%\n",
              label.c_str(), o.all.count, 100 * o.all.median, 100 * o.all.p99, 100 * o.all.max);
  for (int b = 0; b < 3; ++b) {
    std::printf("  theta %s: %zu values, median %.3f %%, p99 %.2f %%, max %.1f %%\n", names[b], o.bands[b].count,
                100 * o.bands[b].median, 100 * o.bands[b].p99, 100 * o.bands[b].max);
  }
  std::printf("  worst: file / table %.3f at theta_i %.1f, theta_o %.1f, delta phi %.1f deg\n", o.worst_ratio,
              o.worst_theta_i, o.worst_theta_o, o.worst_phi);
  std::printf("  reciprocity of the file: median %.3f %%, p99 %.2f %%, max %.1f %%\n", 100 * o.reciprocity.median,
              100 * o.reciprocity.p99, 100 * o.reciprocity.max);
  for (int b = 0; b < 3; ++b) {
    std::printf("  reciprocity, theta %s: median %.3f %%, p99 %.2f %%, max %.1f %%\n", names[b],
                100 * o.reciprocity_bands[b].median, 100 * o.reciprocity_bands[b].p99,
                100 * o.reciprocity_bands[b].max);
  }
  std::printf("  core/rgl_bsdf.h against brdf-loader: max relative difference %.2g\n", o.reader_difference);
}

#endif  // IBRDF_BRDF_LOADER_DIR

// Skips with a message where brdf-loader was not found when CMake ran (a fresh clone has no
// ../shared); the CMake cache variable IBRDF_ORACLES_DIR names the folder.
#ifdef IBRDF_BRDF_LOADER_DIR
#define IBRDF_REQUIRE_BRDF_LOADER()
#else
#define IBRDF_REQUIRE_BRDF_LOADER()                                                                          \
  GTEST_SKIP() << "brdf-loader (powitacq_rgb.h) not found under " IBRDF_ORACLES_DIR                         \
                  "/brdf-loader when CMake ran: set IBRDF_ORACLES_DIR to the folder holding the test oracles " \
                  "(../shared/oracles) and reconfigure"
#endif

TEST(BsdfOracle, DemoSessionThroughBrdfLoader) {
  IBRDF_REQUIRE_BRDF_LOADER();
  ScratchDir dir;
  const Reconstruction r = RunSession(dir, "");
  ASSERT_FALSE(r.bsdf.empty());
  ExpectMitsubaReadsTheFileAsTheOthers(r.bsdf);
#ifdef IBRDF_BRDF_LOADER_DIR
  const OracleFigures o = CompareThroughBrdfLoader(r);
  Print("demo (bluepaint sphere, arc 8-172 deg)", o);
  // The two readers interpolate the file's float32 tables in different orders: 1.06e-4 measured.
  EXPECT_LT(o.reader_difference, 2e-4);
  EXPECT_GT(o.all.count, 100000u);
#endif
}

TEST(BsdfOracle, LightsWithin45DegreesThroughBrdfLoader) {
  IBRDF_REQUIRE_BRDF_LOADER();
  ScratchDir dir;
  const Reconstruction r = RunSession(dir, "--arc-start-deg 8 --arc-end-deg 45");
  ASSERT_FALSE(r.bsdf.empty());
  ExpectMitsubaReadsTheFileAsTheOthers(r.bsdf);
#ifdef IBRDF_BRDF_LOADER_DIR
  const OracleFigures o = CompareThroughBrdfLoader(r);
  Print("lights within 45 deg of the camera (arc 8-45 deg)", o);
  EXPECT_LT(o.reader_difference, 1e-4);
  EXPECT_GT(o.all.count, 10000u);
#endif
}

}  // namespace
}  // namespace ibrdf
