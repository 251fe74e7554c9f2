// The renderer materials of a GGX fit (reconstruct/model_fit.h RendererMaterials) evaluated as the
// renderers evaluate them, with the parameters parsed back from the snippets' text, against the fitted
// BRDF: the median relative error over theta_i, theta_o <= 70 degrees within 5 % for a bluepaint, a
// copper-like and a glossy plastic (the squash recipe's material) fit, and metals keep their colour.
//
// pbrt-v4, re-implemented from its source (src/pbrt/materials.h MixMaterial::ChooseMaterial,
// DiffuseMaterial, ConductorMaterial with "reflectance" or "eta"/"k"; bxdfs.h DiffuseBxDF and
// ConductorBxDF::f; util/scattering.h TrowbridgeReitzDistribution D, Lambda and the height-correlated
// G = 1 / (1 + Lambda(wo) + Lambda(wi)), FrComplex): a "mix" renders the expectation
// (1 - amount) f(materials[0]) + amount f(materials[1]), since ChooseMaterial picks materials[1] when a
// uniform hash u <= amount.
//
// Mitsuba 3, from its sources (src/bsdfs/roughplastic.cpp eval with nonlinear on,
// src/bsdfs/roughconductor.cpp, include/mitsuba/render/fresnel.h fresnel_conductor and
// fresnel_diffuse_reflectance, microfacet.h's GGX D and separable Smith G). One deviation from the
// renderer: roughplastic's transmittance t(cos) is tabulated by Mitsuba by integrating its rough
// dielectric numerically; here it is the smooth interface's 1 - F(cos) (the two differ by under 1 %
// for alpha below 0.3).
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/statistics.h"
#include "reconstruct/model_fit.h"
#include "tests/reconstruct/reconstruct_test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;

// A number or an "r, g, b" triple after name="KEY" value=" in the XML snippet.
Eigen::Vector3d XmlValue(const std::string& xml, const std::string& key) {
  const std::regex pattern("name=\"" + key + "\" value=\"([^\"]+)\"");
  std::smatch match;
  EXPECT_TRUE(std::regex_search(xml, match, pattern)) << key << " in\n" << xml;
  Eigen::Vector3d v;
  const std::string text = match[1];
  if (std::sscanf(text.c_str(), "%lf, %lf, %lf", &v[0], &v[1], &v[2]) != 3)
    v = Eigen::Vector3d::Constant(std::stod(text));
  return v;
}

double GgxD(const Eigen::Vector3d& h, double alpha) {
  const double a2 = alpha * alpha, c2 = h.z() * h.z();
  const double t = c2 * (a2 - 1.0) + 1.0;
  return a2 / (M_PI * t * t);
}
// Smith G1 for GGX as microfacet.h: 2 / (1 + sqrt(1 + alpha^2 tan^2)).
double GgxG1(const Eigen::Vector3d& v, double alpha) {
  const double c2 = v.z() * v.z(), tan2 = (1.0 - c2) / c2;
  return 2.0 / (1.0 + std::sqrt(1.0 + alpha * alpha * tan2));
}
double DielectricF(double cos_i, double eta) {
  const double sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin_t2 >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin_t2);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t), rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}
// fresnel_conductor(cos_theta_i, eta + i k).
double ConductorF(double cos_i, double eta, double k) {
  const double c2 = cos_i * cos_i, s2 = 1.0 - c2, s4 = s2 * s2;
  const double temp1 = eta * eta - k * k - s2;
  const double a2pb2 = std::sqrt(temp1 * temp1 + 4.0 * k * k * eta * eta);
  const double a = std::sqrt(0.5 * (a2pb2 + temp1));
  const double term1 = a2pb2 + c2, term2 = 2.0 * cos_i * a;
  const double rs = (term1 - term2) / (term1 + term2);
  const double term3 = a2pb2 * c2 + s4, term4 = term2 * s2;
  const double rp = rs * (term3 - term4) / (term3 + term4);
  return 0.5 * (rs + rp);
}

// Mitsuba 3's BRDF of the snippet (eval divided by cos_theta_o).
Eigen::Vector3d MitsubaBrdf(const RendererSnippets& s, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  const double alpha = XmlValue(s.mitsuba, "alpha")[0];
  const Eigen::Vector3d h = (wi + wo).normalized();
  const double dg = GgxD(h, alpha) * GgxG1(wi, alpha) * GgxG1(wo, alpha) / (4.0 * wi.z() * wo.z());
  Eigen::Vector3d f;
  if (s.kind == "conductor") {
    const Eigen::Vector3d eta = XmlValue(s.mitsuba, "eta"), k = XmlValue(s.mitsuba, "k");
    for (int c = 0; c < 3; ++c) f[c] = ConductorF(wi.dot(h), eta[c], k[c]) * dg;
    return f;
  }
  const double eta = XmlValue(s.mitsuba, "int_ior")[0];
  const Eigen::Vector3d rho = XmlValue(s.mitsuba, "diffuse_reflectance");
  const double fdr = FresnelDiffuseReflectance(1.0 / eta);
  const double t_i = 1.0 - DielectricF(wi.z(), eta), t_o = 1.0 - DielectricF(wo.z(), eta);
  for (int c = 0; c < 3; ++c) {
    f[c] = DielectricF(wi.dot(h), eta) * dg + rho[c] / (1.0 - rho[c] * fdr) / (eta * eta) * t_i * t_o / M_PI;
  }
  return f;
}

// The numbers after "TYPE KEY" [ ... ] (or a single one without brackets) in the material named
// `material` of a pbrt-v4 snippet (its MakeNamedMaterial block).
Eigen::Vector3d PbrtValue(const std::string& pbrt, const std::string& material, const std::string& type_key) {
  const size_t block = pbrt.find("MakeNamedMaterial \"" + material + "\"\n");
  EXPECT_NE(block, std::string::npos) << material << " in\n" << pbrt;
  const size_t next = pbrt.find("MakeNamedMaterial", block + 1);
  const std::string text = pbrt.substr(block, next == std::string::npos ? std::string::npos : next - block);
  const std::regex pattern("\"" + type_key + "\" \\[? ?([-0-9.eE+]+)(?: ([-0-9.eE+]+) ([-0-9.eE+]+))?");
  std::smatch match;
  EXPECT_TRUE(std::regex_search(text, match, pattern)) << type_key << " in\n" << text;
  if (match[2].matched) return Eigen::Vector3d(std::stod(match[1]), std::stod(match[2]), std::stod(match[3]));
  return Eigen::Vector3d::Constant(std::stod(match[1]));
}

// pbrt-v4's TrowbridgeReitzDistribution (isotropic alpha): D(wm), Lambda(w) and G(wo, wi).
double PbrtD(const Eigen::Vector3d& wm, double alpha) {
  const double cos2 = wm.z() * wm.z(), tan2 = (1.0 - cos2) / cos2, cos4 = cos2 * cos2;
  if (cos4 < 1e-16) return 0.0;
  const double e = tan2 / (alpha * alpha);
  return 1.0 / (M_PI * alpha * alpha * cos4 * (1.0 + e) * (1.0 + e));
}
double PbrtLambda(const Eigen::Vector3d& w, double alpha) {
  const double cos2 = w.z() * w.z(), tan2 = (1.0 - cos2) / cos2;
  return (-1.0 + std::sqrt(1.0 + alpha * alpha * tan2)) / 2.0;
}
// FrComplex(cos_theta_i, eta + i k), as util/scattering.h.
double PbrtFrComplex(double cos_theta_i, double eta, double k) {
  using Complex = std::complex<double>;
  cos_theta_i = std::clamp(cos_theta_i, 0.0, 1.0);
  const Complex n(eta, k);
  const double sin2_i = 1.0 - cos_theta_i * cos_theta_i;
  const Complex sin2_t = sin2_i / (n * n);
  const Complex cos_t = std::sqrt(1.0 - sin2_t);
  const Complex r_parl = (n * cos_theta_i - cos_t) / (n * cos_theta_i + cos_t);
  const Complex r_perp = (cos_theta_i - n * cos_t) / (cos_theta_i + n * cos_t);
  return (std::norm(r_parl) + std::norm(r_perp)) / 2.0;
}
// ConductorBxDF::f: D(wh) G(wo, wi) F(|wi.wh|) / (4 cos_i cos_o).
Eigen::Vector3d PbrtConductor(const Eigen::Vector3d& eta, const Eigen::Vector3d& k, double alpha,
                              const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  const Eigen::Vector3d wh = (wi + wo).normalized();
  const double dg = PbrtD(wh, alpha) / (1.0 + PbrtLambda(wo, alpha) + PbrtLambda(wi, alpha)) / (4.0 * wi.z() * wo.z());
  Eigen::Vector3d f;
  for (int c = 0; c < 3; ++c) f[c] = dg * PbrtFrComplex(std::abs(wi.dot(wh)), eta[c], k[c]);
  return f;
}

// pbrt-v4's BRDF of the snippet: a conductor with "reflectance" (eta 1, k = 2 sqrt(r) / sqrt(1 - r),
// r clamped to 0.9999) or the mix of a diffuse and a conductor with "eta" and "k".
Eigen::Vector3d PbrtBrdf(const RendererSnippets& s, const std::string& name, const Eigen::Vector3d& wi,
                         const Eigen::Vector3d& wo) {
  if (s.kind == "conductor") {
    EXPECT_NE(s.pbrt.find("\"string type\" \"conductor\""), std::string::npos) << s.pbrt;
    const Eigen::Vector3d r = PbrtValue(s.pbrt, name, "rgb reflectance").cwiseMax(0.0).cwiseMin(0.9999);
    Eigen::Vector3d k;
    for (int c = 0; c < 3; ++c) k[c] = 2.0 * std::sqrt(r[c]) / std::sqrt(1.0 - r[c]);
    return PbrtConductor(Eigen::Vector3d::Ones(), k, PbrtValue(s.pbrt, name, "float roughness")[0], wi, wo);
  }
  EXPECT_NE(s.pbrt.find("\"string type\" \"mix\""), std::string::npos) << s.pbrt;
  EXPECT_NE(s.pbrt.find("\"string materials\" [ \"" + name + "-diffuse\" \"" + name + "-specular\" ]"),
            std::string::npos)
      << s.pbrt;
  EXPECT_NE(s.pbrt.find("bool remaproughness\" false"), std::string::npos) << s.pbrt;
  const double amount = PbrtValue(s.pbrt, name, "float amount")[0];
  const Eigen::Vector3d rho = PbrtValue(s.pbrt, name + "-diffuse", "rgb reflectance").cwiseMax(0.0).cwiseMin(1.0);
  const Eigen::Vector3d eta = PbrtValue(s.pbrt, name + "-specular", "rgb eta");
  const Eigen::Vector3d k = PbrtValue(s.pbrt, name + "-specular", "rgb k");
  const double alpha = PbrtValue(s.pbrt, name + "-specular", "float roughness")[0];
  return (1.0 - amount) * rho / M_PI + amount * PbrtConductor(eta, k, alpha, wi, wo);
}

using RendererBrdf = std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&)>;

// Median |relative error| of the renderer's BRDF against the fit over theta_i, theta_o <= 70 degrees
// (5-degree steps, delta_phi in 15-degree steps), overall and by band of max(theta_i, theta_o); the
// 95th percentile is printed too (the specular peaks, where a mix's Fresnel is approximate).
double MedianError(const ModelFitResult& fit, const RendererBrdf& renderer, const std::string& label) {
  std::vector<double> all, bands[3];
  for (int ti = 0; ti <= 70; ti += 5) {
    for (int to = 0; to <= 70; to += 5) {
      for (int dp = 0; dp <= 180; dp += 15) {
        const Eigen::Vector3d wi = FromSpherical(std::max(ti, 1) * M_PI / 180.0, 0.0);
        const Eigen::Vector3d wo = FromSpherical(std::max(to, 1) * M_PI / 180.0, dp * M_PI / 180.0);
        const Eigen::Vector3d f = fit.brdf->Eval(wi, wo), r = renderer(wi, wo);
        for (int c = 0; c < 3; ++c) {
          if (!(f[c] > 1e-6)) continue;
          const double e = std::abs(r[c] - f[c]) / f[c];
          all.push_back(e);
          bands[std::min(2, std::max(ti, to) / 25)].push_back(e);
        }
      }
    }
  }
  std::vector<double> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  std::printf("%s: median |rel. error| %.2f %% (theta 0-25: %.2f %%, 25-50: %.2f %%, 50-70: %.2f %%), p95 %.2f %%\n",
              label.c_str(), 100 * Median(all), 100 * Median(bands[0]), 100 * Median(bands[1]), 100 * Median(bands[2]),
              100 * sorted[size_t(0.95 * double(sorted.size() - 1))]);
  return Median(all);
}

ModelFitResult GgxFitOf(const BrdfModel& truth) {
  const auto samples = testing::SessionSamples(truth, CameraEffects::None(), 10, 200, 150);
  ModelFitOptions options;
  options.max_samples = 4000;
  return FitGgx(samples, options);
}

// Both renderers' BRDFs of the three fits, within 5 % median of the fitted BRDF.
TEST(RendererSnippets, PbrtAndMitsubaRenderWhatWasFitted) {
  const GgxBrdf copper(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25);
  const auto bluepaint = LoadMaterial(MaterialPath("bluepaint"));
  const auto glossy = LoadMaterial(MaterialPath("glossy-ggx"));
  const std::pair<std::string, const BrdfModel*> cases[] = {
      {"bluepaint", bluepaint.get()}, {"copper-like", &copper}, {"glossy-ggx (squash)", glossy.get()}};
  for (const auto& [label, truth] : cases) {
    const ModelFitResult fit = GgxFitOf(*truth);
    ASSERT_TRUE(fit.success);
    std::printf("%s: %s\n", label.c_str(), fit.BriefReport().c_str());
    const RendererSnippets snippets = RendererMaterials(fit, "m", "linear sRGB (D65)");
    EXPECT_EQ(snippets.kind, label == "copper-like" ? "conductor" : "plastic") << fit.brdf->ToJson().dump();
    const RendererBrdf pbrt = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
      return PbrtBrdf(snippets, "m", wi, wo);
    };
    const RendererBrdf mitsuba = [&](const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
      return MitsubaBrdf(snippets, wi, wo);
    };
    EXPECT_LT(MedianError(fit, pbrt, label + " pbrt-v4 " + snippets.kind), 0.05) << label << "\n" << snippets.pbrt;
    EXPECT_LT(MedianError(fit, mitsuba, label + " Mitsuba 3 " + snippets.kind), 0.05) << label << "\n"
                                                                                      << snippets.mitsuba;
  }
}

// The library's conductor Fresnel (used to fit the mix's conductor) is pbrt's FrComplex and Mitsuba's
// fresnel_conductor (two independent forms of the same equations), and the dielectric one with k = 0.
TEST(RendererSnippets, ComplexFresnelMatchesBothRenderers) {
  for (double cos_i : {1.0, 0.9, 0.6, 0.3, 0.05}) {
    for (const auto& [eta, k] :
         std::vector<std::pair<double, double>>{{1.5, 0.0}, {0.7, 0.6}, {0.27, 3.6}, {1.0, 0.0}}) {
      EXPECT_NEAR(ComplexFresnel(cos_i, eta, k), PbrtFrComplex(cos_i, eta, k), 1e-12);
      EXPECT_NEAR(ComplexFresnel(cos_i, eta, k), ConductorF(cos_i, eta, k), 1e-9) << cos_i << " " << eta << " " << k;
    }
    EXPECT_NEAR(ComplexFresnel(cos_i, 1.5, 0.0), DielectricF(cos_i, 1.5), 1e-12);
  }
  EXPECT_EQ(ComplexFresnel(0.5, 1.0, 0.0), 0.0);
}

// The mix's parameters are valid for pbrt: reflectance in [0, 1], amount in [0, 1], the diffuse part
// exactly the fitted one, and a vanishing specular term (F0 = 0, dielectric) stays exactly 0.
TEST(RendererSnippets, PbrtMixKeepsTheDiffuseExactAndZeroSpecularZero) {
  const Eigen::Vector3d d(0.5, 0.12, 0.08);
  const PbrtMixParameters mix = PbrtMixFromGgx(d, Eigen::Vector3d::Constant(0.04), 0.15, true);
  EXPECT_NEAR(mix.amount, 0.5, 1e-12);
  EXPECT_LE(mix.reflectance.maxCoeff(), 1.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR((1.0 - mix.amount) * mix.reflectance[c], d[c], 1e-12);
  for (int c = 0; c < 3; ++c) EXPECT_LT(mix.fresnel_rel_rms[c], 0.1) << c;
  // Near normal incidence the mix's Fresnel is the fitted one within 3 %.
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(mix.amount * ComplexFresnel(1.0, mix.eta[c], mix.k[c]), 0.04, 0.03 * 0.04) << c;
  }
  const PbrtMixParameters lambertian = PbrtMixFromGgx(d, Eigen::Vector3d::Zero(), 0.15, true);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(ComplexFresnel(0.7, lambertian.eta[c], lambertian.k[c]), 0.0, 1e-12);
}

TEST(RendererSnippets, MetalsKeepTheirColour) {
  const GgxBrdf copper(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25);
  ModelFitResult fit;
  fit.model = "ggx";
  fit.brdf = std::make_unique<GgxBrdf>(copper);
  const RendererSnippets snippets = RendererMaterials(fit, "copper");
  ASSERT_EQ(snippets.kind, "conductor");
  EXPECT_NE(snippets.pbrt.find("\"string type\" \"conductor\""), std::string::npos) << snippets.pbrt;
  EXPECT_NE(snippets.pbrt.find("\"rgb reflectance\" [ 0.95 0.64 0.54 ]"), std::string::npos) << snippets.pbrt;
  EXPECT_NE(snippets.pbrt.find("MakeNamedMaterial \"copper\""), std::string::npos);
  // At normal incidence the conductor's Fresnel is the fitted F0 in every channel.
  const Eigen::Vector3d eta = XmlValue(snippets.mitsuba, "eta"), k = XmlValue(snippets.mitsuba, "k");
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(ConductorF(1.0, eta[c], k[c]), copper.ToJson()["specular_f0"][c].get<double>(), 1e-4);
  // So is pbrt-v4's, rendering the snippet: at normal incidence D G / (4 cos^2) is 1 / (4 pi alpha^2).
  const Eigen::Vector3d n(0.0, 0.0, 1.0);
  const Eigen::Vector3d f = PbrtBrdf(snippets, "copper", n, n) * (4.0 * M_PI * 0.25 * 0.25);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], copper.ToJson()["specular_f0"][c].get<double>(), 1e-4);
}

// The snippets state the samples' colour space and warn where a renderer would misread the values.
TEST(RendererSnippets, StateTheColourSpaceAndWarnWhenNotLinearSrgb) {
  ModelFitResult fit;
  fit.model = "ggx";
  fit.brdf = std::make_unique<GgxBrdf>(Eigen::Vector3d(0.5, 0.12, 0.08), Eigen::Vector3d::Constant(0.04), 0.15,
                                       GgxFresnel::kDielectric);
  const std::string srgb = "linear sRGB (D65): camera RGB through the colour chart's matrix (see \"colour\")";
  const std::string camera = "camera RGB, linear (the session's response inverted, black level subtracted)";
  const std::string xyz = "CIE XYZ (D65): camera RGB through the colour chart's matrix (see \"colour\")";
  // A space from elsewhere with a line break and "--" keeps each snippet's comments well-formed.
  const RendererSnippets odd = RendererMaterials(fit, "m", "camera RGB\n--raw");
  EXPECT_NE(odd.pbrt.find("# Colour space of the values: camera RGB - -raw."), std::string::npos) << odd.pbrt;
  EXPECT_NE(odd.mitsuba.find("<!-- Colour space of the values: camera RGB - -raw. -->"), std::string::npos)
      << odd.mitsuba;
  for (const std::string& space : {srgb, camera, xyz, std::string()}) {
    for (bool metal : {false, true}) {
      if (metal) fit.brdf = std::make_unique<GgxBrdf>(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.2);
      const RendererSnippets snippets = RendererMaterials(fit, "m", space);
      const std::string stated = space.empty() ? "unknown" : space;
      EXPECT_NE(snippets.pbrt.find("# Colour space of the values: " + stated), std::string::npos) << snippets.pbrt;
      EXPECT_NE(snippets.mitsuba.find("<!-- Colour space of the values: " + stated), std::string::npos)
          << snippets.mitsuba;
      const bool warned = space != srgb;
      EXPECT_EQ(snippets.pbrt.find("WARNING: not linear sRGB") != std::string::npos, warned) << snippets.pbrt;
      EXPECT_EQ(snippets.mitsuba.find("WARNING: not linear sRGB") != std::string::npos, warned) << snippets.mitsuba;
      // An XML comment may not hold "--": the only ones are the comments' own delimiters.
      size_t dashes = 0;
      for (size_t at = snippets.mitsuba.find("--"); at != std::string::npos; at = snippets.mitsuba.find("--", at + 2))
        ++dashes;
      size_t comments = 0;
      for (size_t at = snippets.mitsuba.find("<!--"); at != std::string::npos;
           at = snippets.mitsuba.find("<!--", at + 4))
        ++comments;
      EXPECT_EQ(dashes, 2 * comments) << snippets.mitsuba;
    }
    fit.brdf = std::make_unique<GgxBrdf>(Eigen::Vector3d(0.5, 0.12, 0.08), Eigen::Vector3d::Constant(0.04), 0.15,
                                         GgxFresnel::kDielectric);
  }
}

}  // namespace
}  // namespace ibrdf
