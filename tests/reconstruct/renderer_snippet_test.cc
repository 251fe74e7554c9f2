// The renderer materials of a GGX fit (reconstruct/model_fit.h RendererMaterials) evaluated as the
// renderers evaluate them, re-implemented here from Mitsuba 3's sources (src/bsdfs/roughplastic.cpp
// eval with nonlinear on, src/bsdfs/roughconductor.cpp, include/mitsuba/render/fresnel.h
// fresnel_conductor and fresnel_diffuse_reflectance, microfacet.h's GGX D and separable Smith G), with
// the parameters parsed back from the snippet's text, against the fitted BRDF: the median relative
// error over theta_i, theta_o <= 70 degrees within 5 % for a bluepaint, a copper-like and a glossy
// plastic (the squash recipe's material) fit, and metals keep their colour. One deviation from the
// renderer: roughplastic's transmittance t(cos) is tabulated by Mitsuba by integrating its rough
// dielectric numerically; here it is the smooth interface's 1 - F(cos) (the two differ by under 1 %
// for alpha below 0.3).
#include <cmath>
#include <cstdio>
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

// Median |relative error| of the renderer's BRDF against the fit over theta_i, theta_o <= 70 degrees
// (5-degree steps, delta_phi in 15-degree steps), overall and by band of max(theta_i, theta_o).
double MedianError(const ModelFitResult& fit, const RendererSnippets& snippets, const std::string& label) {
  std::vector<double> all, bands[3];
  for (int ti = 0; ti <= 70; ti += 5) {
    for (int to = 0; to <= 70; to += 5) {
      for (int dp = 0; dp <= 180; dp += 15) {
        const Eigen::Vector3d wi = FromSpherical(std::max(ti, 1) * M_PI / 180.0, 0.0);
        const Eigen::Vector3d wo = FromSpherical(std::max(to, 1) * M_PI / 180.0, dp * M_PI / 180.0);
        const Eigen::Vector3d f = fit.brdf->Eval(wi, wo), r = MitsubaBrdf(snippets, wi, wo);
        for (int c = 0; c < 3; ++c) {
          if (!(f[c] > 1e-6)) continue;
          const double e = std::abs(r[c] - f[c]) / f[c];
          all.push_back(e);
          bands[std::min(2, std::max(ti, to) / 25)].push_back(e);
        }
      }
    }
  }
  std::printf("%s (%s): median |rel. error| %.2f %% (theta 0-25: %.2f %%, 25-50: %.2f %%, 50-70: %.2f %%)\n",
              label.c_str(), snippets.kind.c_str(), 100 * Median(all), 100 * Median(bands[0]), 100 * Median(bands[1]),
              100 * Median(bands[2]));
  return Median(all);
}

ModelFitResult GgxFitOf(const BrdfModel& truth) {
  const auto samples = testing::SessionSamples(truth, CameraEffects::None(), 10, 200, 150);
  ModelFitOptions options;
  options.max_samples = 4000;
  return FitGgx(samples, options);
}

TEST(RendererSnippets, MitsubaRendersWhatWasFitted) {
  const GgxBrdf copper(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.95, 0.64, 0.54), 0.25);
  const auto bluepaint = LoadMaterial(MaterialPath("bluepaint"));
  const auto glossy = LoadMaterial(MaterialPath("glossy-ggx"));
  const std::pair<std::string, const BrdfModel*> cases[] = {
      {"bluepaint", bluepaint.get()}, {"copper-like", &copper}, {"glossy-ggx (squash)", glossy.get()}};
  for (const auto& [label, truth] : cases) {
    const ModelFitResult fit = GgxFitOf(*truth);
    ASSERT_TRUE(fit.success);
    const RendererSnippets snippets = RendererMaterials(fit, "m");
    EXPECT_LT(MedianError(fit, snippets, label), 0.05) << label << "\n" << snippets.mitsuba;
    EXPECT_EQ(snippets.kind, label == "copper-like" ? "conductor" : "plastic") << fit.brdf->ToJson().dump();
  }
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
}

}  // namespace
}  // namespace ibrdf
