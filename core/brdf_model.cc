#include "core/brdf_model.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "core/rgl_bsdf.h"

namespace ibrdf {

Eigen::Vector3d LambertianBrdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (!(wi.z() > 0.0) || !(wo.z() > 0.0)) return Eigen::Vector3d::Zero();
  return albedo_ / M_PI;
}

nlohmann::json LambertianBrdf::ToJson() const { return {{"model", "lambertian"}, {"albedo", ibrdf::ToJson(albedo_)}}; }

Eigen::Vector3d LafortuneBrdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (!(wi.z() > 0.0) || !(wo.z() > 0.0)) return Eigen::Vector3d::Zero();
  const double xy = wi.x() * wo.x() + wi.y() * wo.y();
  const double z = wi.z() * wo.z();
  Eigen::Vector3d f = diffuse_ / M_PI;
  for (const LafortuneLobe& lobe : lobes_) {
    for (int c = 0; c < 3; ++c) {
      const double base = lobe.cxy[c] * xy + lobe.cz[c] * z;
      if (base > 0.0) f[c] += std::pow(base, lobe.n[c]);
    }
  }
  return f;
}

nlohmann::json LafortuneBrdf::ToJson() const {
  nlohmann::json lobes = nlohmann::json::array();
  for (const LafortuneLobe& lobe : lobes_) {
    lobes.push_back({{"Cxy", ibrdf::ToJson(lobe.cxy)}, {"Cz", ibrdf::ToJson(lobe.cz)}, {"n", ibrdf::ToJson(lobe.n)}});
  }
  return {{"model", "lafortune"}, {"diffuse", ibrdf::ToJson(diffuse_)}, {"lobes", lobes}};
}

Eigen::Vector3d GgxBrdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (!(wi.z() > 0.0) || !(wo.z() > 0.0)) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d h = (wi + wo).normalized();
  const double a2 = alpha_ * alpha_;
  const double cos_h = h.z();
  const double denominator = cos_h * cos_h * (a2 - 1.0) + 1.0;
  const double d = a2 / (M_PI * denominator * denominator);
  // Smith G1 for GGX in its tan-free form: 2 cos / (cos + sqrt(a2 + (1 - a2) cos^2)).
  auto g1 = [a2](double cos_theta) {
    return 2.0 * cos_theta / (cos_theta + std::sqrt(a2 + (1.0 - a2) * cos_theta * cos_theta));
  };
  const double g = g1(wi.z()) * g1(wo.z());
  Eigen::Vector3d fresnel;
  if (fresnel_ == GgxFresnel::kDielectric) {
    for (int c = 0; c < 3; ++c) fresnel[c] = DielectricFresnel(wi.dot(h), IorFromF0(specular_f0_[c]));
  } else {
    const double schlick = std::pow(1.0 - std::max(0.0, wi.dot(h)), 5.0);
    fresnel = specular_f0_ + (Eigen::Vector3d::Ones() - specular_f0_) * schlick;
  }
  return diffuse_albedo_ / M_PI + fresnel * (d * g / (4.0 * wi.z() * wo.z()));
}

double DielectricFresnel(double cos_theta, double eta) {
  const double c = std::clamp(std::abs(cos_theta), 0.0, 1.0);
  const double g2 = eta * eta - 1.0 + c * c;
  if (g2 < 0.0) return 1.0;  // total internal reflection (eta < 1 only)
  const double g = std::sqrt(g2);
  if (g + c == 0.0) return 1.0;
  const double a = (g - c) / (g + c), b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

double IorFromF0(double f0) {
  const double s = std::sqrt(std::clamp(f0, 0.0, 0.999999));
  return (1.0 + s) / (1.0 - s);
}

nlohmann::json GgxBrdf::ToJson() const {
  nlohmann::json json = {{"model", "ggx"},
                         {"diffuse_albedo", ibrdf::ToJson(diffuse_albedo_)},
                         {"specular_f0", ibrdf::ToJson(specular_f0_)},
                         {"alpha", alpha_}};
  if (fresnel_ == GgxFresnel::kDielectric) json["fresnel"] = "dielectric";
  return json;
}

namespace {
Eigen::Vector3d NonNegative(JsonObject& object, const std::string& key) {
  const Eigen::Vector3d v = object.Vector3(key);
  if (!v.allFinite() || (v.array() < 0.0).any()) ThrowError(object.Where(key), "expected non-negative values");
  return v;
}

// An albedo or reflectance: in [0, 1] (energy conservation of the diffuse term); a material on a
// relative scale ("scale": "relative": measured under lights whose common intensity is unknown) is
// its true values times one unknown constant, so only finite and non-negative, at most 1e6.
Eigen::Vector3d Reflectance(JsonObject& object, const std::string& key, bool relative) {
  const Eigen::Vector3d v = NonNegative(object, key);
  if (relative) {
    if ((v.array() > 1e6).any()) ThrowError(object.Where(key), "expected relative reflectances of at most 1e6");
    return v;
  }
  if ((v.array() > 1.0).any()) {
    ThrowError(object.Where(key), "expected reflectances in [0, 1] (a material measured on a relative scale says "
                                  "\"scale\": \"relative\")");
  }
  return v;
}

// Lafortune lobe coefficients: |C| <= 10 and 0 < n <= 10000, and a lobe peak max(|Cxy|, |Cz|)^n of at
// most 1e6 /sr (a material with Cz 1e300 made synth expose its photos for 0 s).
void CheckLobe(const LafortuneLobe& lobe, JsonObject& object) {
  constexpr double kMaxCoefficient = 10.0, kMaxExponent = 1e4, kMaxPeak = 1e6;
  for (int c = 0; c < 3; ++c) {
    if (!(std::abs(lobe.cxy[c]) <= kMaxCoefficient)) ThrowError(object.Where("Cxy"), "expected |Cxy| <= 10");
    if (!(std::abs(lobe.cz[c]) <= kMaxCoefficient)) ThrowError(object.Where("Cz"), "expected |Cz| <= 10");
    if (!(lobe.n[c] > 0.0 && lobe.n[c] <= kMaxExponent)) {
      ThrowError(object.Where("n"), "exponents must be positive and at most 10000");
    }
    const double peak = std::pow(std::max(std::abs(lobe.cxy[c]), std::abs(lobe.cz[c])), lobe.n[c]);
    if (!(peak <= kMaxPeak)) {
      ThrowError(object.Where(), "the lobe peaks at " + std::to_string(peak) +
                                     " /sr (max(|Cxy|, |Cz|)^n); at most 1e6 is physically plausible");
    }
  }
}
}  // namespace

std::unique_ptr<BrdfModel> MaterialFromJson(const nlohmann::json& value, const std::string& file,
                                            const std::string& pointer) {
  JsonObject object(value, file, pointer);
  object.String("name", "");
  object.String("description", "");
  object.String("source", "");
  object.String("colour_space", "");  // the values' colour space (fits state their samples'); informative
  const std::string scale = object.String("scale", "absolute");
  if (scale != "absolute" && scale != "relative") {
    ThrowError(object.Where("scale"), "expected \"absolute\" or \"relative\", got \"" + scale + "\"");
  }
  const bool relative = scale == "relative";
  const std::string model = object.String("model");
  std::unique_ptr<BrdfModel> brdf;
  if (model == "lambertian") {
    brdf = std::make_unique<LambertianBrdf>(Reflectance(object, "albedo", relative));
  } else if (model == "lafortune") {
    const Eigen::Vector3d diffuse = Reflectance(object, "diffuse", relative);
    std::vector<LafortuneLobe> lobes;
    for (JsonObject& lobe_object : object.Objects("lobes")) {
      LafortuneLobe lobe;
      lobe.cxy = lobe_object.Vector3("Cxy");
      lobe.cz = lobe_object.Vector3("Cz");
      lobe.n = lobe_object.Vector3("n");
      CheckLobe(lobe, lobe_object);
      lobe_object.Finish();
      lobes.push_back(lobe);
    }
    brdf = std::make_unique<LafortuneBrdf>(diffuse, std::move(lobes));
  } else if (model == "ggx") {
    const Eigen::Vector3d diffuse = Reflectance(object, "diffuse_albedo", relative);
    const Eigen::Vector3d f0 = Reflectance(object, "specular_f0", relative);
    const double alpha = object.Number("alpha");
    if (!(alpha > 0.0 && alpha <= 1.0)) ThrowError(object.Where("alpha"), "expected 0 < alpha <= 1");
    const std::string fresnel = object.String("fresnel", "schlick");
    if (fresnel != "schlick" && fresnel != "dielectric") {
      ThrowError(object.Where("fresnel"), "expected \"schlick\" or \"dielectric\", got \"" + fresnel + "\"");
    }
    if (fresnel == "dielectric" && (f0.array() >= 1.0).any()) {
      ThrowError(object.Where("specular_f0"), "expected values below 1 with a dielectric Fresnel");
    }
    brdf = std::make_unique<GgxBrdf>(diffuse, f0, alpha,
                                     fresnel == "dielectric" ? GgxFresnel::kDielectric : GgxFresnel::kSchlick);
  } else if (model == "merl") {
    std::filesystem::path table = object.String("file");
    if (table.is_relative() && !file.empty()) table = std::filesystem::path(file).parent_path() / table;
    brdf = std::make_unique<MerlBrdf>(table.string(),
                                      MerlLookupFromName(object.String("lookup", "nearest"), object.Where("lookup")));
  } else if (model == "rgl_bsdf") {
    std::filesystem::path table = object.String("file");
    if (table.is_relative() && !file.empty()) table = std::filesystem::path(file).parent_path() / table;
    brdf = std::make_unique<RglBsdf>(table.string());
  } else {
    ThrowError(object.Where("model"),
               "unknown model \"" + model + "\" (expected lambertian, lafortune, ggx, merl or rgl_bsdf)");
  }
  object.Finish();
  return brdf;
}

std::unique_ptr<BrdfModel> LoadMaterial(const std::string& path) {
  if (IsMerlPath(path)) return std::make_unique<MerlBrdf>(path);
  if (IsRglBsdfPath(path)) return std::make_unique<RglBsdf>(path);
  return MaterialFromJson(ReadJsonFile(path), path);
}

}  // namespace ibrdf
