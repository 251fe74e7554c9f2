// Analytic BRDF models: the materials of synthetic sessions and the ground truth they are compared to.
//
// Every model is isotropic and evaluated in the local frame (z = normal) on unit directions wi
// (towards the light) and wo (towards the camera); below the horizon it is 0. Values are RGB, 1/sr.
//
// Material files (samples/materials/*.json) are JSON objects with "model" and the model's parameters:
//   lambertian: "albedo": [r, g, b]                      f = albedo / pi
//   lafortune:  "diffuse": [r, g, b], "lobes": [{"Cxy": [r,g,b], "Cz": [r,g,b], "n": [r,g,b]}, ...]
//               f = diffuse/pi + sum_k max(0, Cxy_k (wi.x wo.x + wi.y wo.y) + Cz_k wi.z wo.z)^n_k
//               (Lafortune et al. 1997, as in the pbrt fits of the seed paper's materials)
//   ggx:        "diffuse_albedo": [r,g,b], "specular_f0": [r,g,b], "alpha": a
//               f = diffuse_albedo/pi + D(h) G(wi, wo) F(wi.h) / (4 cos_i cos_o), GGX D (Walter et al.
//               2007), separable Smith shadowing for GGX, Schlick's Fresnel F0 + (1 - F0)(1 - cos)^5
//               (a conductor-like Fresnel: F0 per channel rising to 1 at grazing); with
//               "fresnel": "dielectric" the exact unpolarized dielectric Fresnel of the IOR with that
//               F0 per channel, eta = (1 + sqrt(F0)) / (1 - sqrt(F0)), which vanishes with F0 = 0 (a
//               pure Lambertian is then representable; Schlick's term stays non-zero at grazing)
//   merl:       "file": "x.binary"  a MERL table (core/merl_brdf.h), looked up as the MERL reader does
//   rgl_bsdf:   "file": "x.bsdf"    an RGL tensor file (core/rgl_bsdf.h), evaluated as brdf-loader does
// plus optional "name", "description", "source" and "colour_space" strings (the last: the space the
// values are in, e.g. "linear sRGB (D65) ..." or "camera RGB ..."; fits state their samples').
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

namespace ibrdf {

class BrdfModel {
 public:
  virtual ~BrdfModel() = default;
  // f(wi, wo), RGB in 1/sr; 0 when either direction is below the horizon.
  virtual Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const = 0;
  // The material file's JSON for this model (round-trips through MaterialFromJson).
  virtual nlohmann::json ToJson() const = 0;
  // "lambertian", "lafortune" or "ggx".
  virtual std::string ModelName() const = 0;
};

class LambertianBrdf : public BrdfModel {
 public:
  explicit LambertianBrdf(const Eigen::Vector3d& albedo) : albedo_(albedo) {}
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override;
  nlohmann::json ToJson() const override;
  std::string ModelName() const override { return "lambertian"; }
  const Eigen::Vector3d& albedo() const { return albedo_; }

 private:
  Eigen::Vector3d albedo_;
};

struct LafortuneLobe {
  Eigen::Vector3d cxy, cz, n;  // per channel
};

class LafortuneBrdf : public BrdfModel {
 public:
  LafortuneBrdf(const Eigen::Vector3d& diffuse, std::vector<LafortuneLobe> lobes)
      : diffuse_(diffuse), lobes_(std::move(lobes)) {}
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override;
  nlohmann::json ToJson() const override;
  std::string ModelName() const override { return "lafortune"; }
  const Eigen::Vector3d& diffuse() const { return diffuse_; }
  const std::vector<LafortuneLobe>& lobes() const { return lobes_; }

 private:
  Eigen::Vector3d diffuse_;
  std::vector<LafortuneLobe> lobes_;
};

// The Fresnel term of a GgxBrdf.
enum class GgxFresnel : uint8_t {
  kSchlick = 0,     // F0 + (1 - F0)(1 - cos)^5 per channel: conductor-like, never 0 at grazing
  kDielectric = 1,  // exact dielectric Fresnel of eta(F0) per channel: 0 everywhere with F0 = 0
};

// The unpolarized Fresnel reflectance of a dielectric interface of relative IOR eta >= 1 for light
// arriving at cos_theta from the outside (Walter et al. 2007, eq. 22); 0 for eta = 1.
double DielectricFresnel(double cos_theta, double eta);
// The IOR whose normal-incidence reflectance is f0 in [0, 1): (1 + sqrt(f0)) / (1 - sqrt(f0)).
double IorFromF0(double f0);

class GgxBrdf : public BrdfModel {
 public:
  GgxBrdf(const Eigen::Vector3d& diffuse_albedo, const Eigen::Vector3d& specular_f0, double alpha,
          GgxFresnel fresnel = GgxFresnel::kSchlick)
      : diffuse_albedo_(diffuse_albedo), specular_f0_(specular_f0), alpha_(alpha), fresnel_(fresnel) {}
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override;
  nlohmann::json ToJson() const override;
  std::string ModelName() const override { return "ggx"; }

 private:
  Eigen::Vector3d diffuse_albedo_;
  Eigen::Vector3d specular_f0_;
  double alpha_;  // GGX roughness (the slope distribution's width)
  GgxFresnel fresnel_;
};

// Reads a material from JSON; `where` names the source for errors (a file, or "file: /pointer").
std::unique_ptr<BrdfModel> MaterialFromJson(const nlohmann::json& value, const std::string& file,
                                            const std::string& pointer = "");

// Reads a material file (see the format above), a MERL table (a ".binary" path, core/merl_brdf.h) or an
// RGL tensor file (a ".bsdf" path, core/rgl_bsdf.h).
std::unique_ptr<BrdfModel> LoadMaterial(const std::string& path);

}  // namespace ibrdf
