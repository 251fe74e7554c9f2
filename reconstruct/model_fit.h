// Analytic model fits of measured samples with Ceres (the paper fits a multi-lobe Lafortune model for
// rendering, section 5): a robust (Huber) loss on residuals weighted by each sample's uncertainty, the
// sample file's sigma column with a floor. Parameters come out as a material file (samples/materials
// format, so `ibrdf synth --material` renders the fit) and, for the microfacet fit, as material
// snippets for pbrt-v4 and Mitsuba 3.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/brdf_model.h"
#include "core/sample_file.h"

namespace ibrdf {

struct ModelFitOptions {
  int lafortune_lobes = 3;       // 1 to 3 lobes
  size_t max_samples = 20000;    // a random subset (fixed seed) of at most this many samples is fitted
  double relative_floor = 0.01;  // sigma is at least this fraction of the value (noise-free samples)
  double absolute_floor = 1e-4;  // and at least this (1/sr)
  double huber_scale = 3.0;      // Huber loss threshold, in sigmas
  int max_iterations = 200;      // per Ceres solve
  // The starting points are compared on a random subset of at most this many of the fitted samples
  // (fixed seed); the best (Lafortune: per channel; GGX: per Fresnel variant) is then refined on all
  // of them (0: every start solved on all).
  size_t start_samples = 4000;
  double start_tolerance = 1e-6;  // Ceres function and parameter tolerance of those solves (ranking only)
  double max_theta_deg = 80.0;    // samples beyond this theta_i or theta_e are left out
  // A Lafortune lobe's largest value anywhere, max(|Cxy|, |Cz|)^n, is held below a cap (a penalty), so
  // no lobe grows without bound towards unsampled directions: max_lobe_ratio times the largest sample
  // value, or min_lobe_cap where that is higher (a lobe whose base never exceeds 1, |Cxy|, |Cz| <= 1,
  // is bounded by 1 /sr whatever its exponent: a dull material keeps the narrow grazing lobe its
  // samples show, felt's retro-reflection), but that floor at most max_lobe_floor_ratio times the
  // largest sample (samples in arbitrary units, relative light intensities, must not loosen the cap
  // without bound). docs/reconstruct.md, "Plausible where no camera looked".
  double max_lobe_ratio = 3.0;
  double min_lobe_cap = 1.0;           // 1/sr
  double max_lobe_floor_ratio = 30.0;  // times the largest sample
  // Directional albedo at most 1 (energy conservation) is a constraint of every solve: a penalty on a
  // fixed quadrature (8 incidence angles, 16 x 32 exitant cells), checked after on the dense grid of
  // MaxDirectionalAlbedo and the solve tightened where that grid finds it above. With `relative_scale`
  // (lights of relative intensity: every value is the material's times one unknown constant) 1 means
  // nothing; the bound is then pi times the channel's largest sample, the albedo of a surface as
  // bright as the brightest sample everywhere (docs/decisions.md, "Fit plausibility").
  bool relative_scale = false;
  // Retro-reflection (theta_d below the samples' smallest, where no camera can look: it would stand in
  // the light) is held below this many times the largest sample at the same theta_h (within 2.5
  // degrees): a penalty at probe directions (theta_d 0 and half the smallest sampled) every 2 degrees
  // of theta_h up to max_theta_deg. Beyond the samples' theta the lobe cap above is the bound.
  double max_unmeasured_ratio = 2.0;
  // A fit is plausible when its dense albedo is within this fraction above its bound and no probe above
  // its ceiling by more; an implausible fit is reported and never chosen by the reconstruct stage.
  double plausibility_tolerance = 0.02;
  // False: the solves leave the albedo bound and the retro-reflection ceilings out (the fit is still
  // judged against them); for comparisons only.
  bool plausibility_constraints = true;
  uint64_t seed = 1;
  bool Check(std::string* why) const;
};

struct ModelFitResult {
  bool success = false;
  std::string model;  // "lafortune" or "ggx"
  std::unique_ptr<BrdfModel> brdf;
  size_t samples_used = 0;
  double final_cost = 0.0;   // Ceres cost, summed over the channel fits
  double rel_rms = 0.0;      // RMS of (f_fit - f) / f over the samples used and channels
  int starts = 0;            // initial guesses tried (the best is kept)
  size_t start_samples = 0;  // the samples the starts were ranked on (0: all of them)
  // Parameters that ended at a bound of the fit ("n lobe 1 G at 2000"): reported, never silent.
  std::vector<std::string> at_bound;
  // Lafortune lobes whose max(|Cxy|, |Cz|)^n is within 1 % of the lobe cap (ModelFitOptions::
  // max_lobe_ratio): the cap, not the samples, holds them ("lobe 1 G at 1 /sr").
  std::vector<std::string> at_lobe_cap;
  // The largest directional albedo over a dense grid of incidence directions on the whole hemisphere
  // (0 to 89.5 degrees), per channel's max; a plausible BRDF keeps it at most albedo_bound (1, or in
  // relative sessions pi times the largest sample: ModelFitOptions::relative_scale).
  double max_albedo = 0.0;
  double albedo_bound = 1.0;  // the largest of the channels' bounds
  bool relative_scale = false;
  // The fit's largest value at the retro-reflection probes over the largest sample beside each (its
  // ceiling is ModelFitOptions::max_unmeasured_ratio times that); 0 where retro-reflection was sampled.
  double max_retro_ratio = 0.0;
  double theta_d_min_deg = 0.0;  // the samples' smallest theta_d (retro-reflection is theta_d 0)
  size_t retro_probes = 0;       // retro-reflection probes (none where theta_d_min_deg is below 1 degree)
  // Channels held by a plausibility bound rather than by the samples ("albedo G at its bound 1",
  // "retro-reflection R at its ceiling at 12 of 120 probes").
  std::vector<std::string> held_by_plausibility;
  // Channels whose retro-reflection at 85 or 89 degrees, beyond the samples' theta, exceeds
  // ModelFitOptions::max_unmeasured_ratio times the samples beside the last probe: bounded there by the
  // lobe cap only (a real grazing peak such as felt's is kept), so said.
  std::vector<std::string> beyond_samples;
  // False with the reasons where the fit breaks a plausibility bound even so; the stage never chooses it.
  bool plausible = true;
  std::vector<std::string> implausible;
  // Relative RMS against the samples used by band of max(theta_i, theta_o): 0-25, 25-50, 50-80 degrees,
  // over the channels each sample measured.
  std::vector<double> band_rel_rms;
  // GGX: the Fresnel variant kept ("dielectric": exact Fresnel of eta(F0), vanishing with F0 = 0;
  // "conductor": Schlick per channel, F0 rising to 1 at grazing, as a metal) and every variant tried
  // with its relative RMS against the samples; the lower error wins.
  std::string variant;
  std::vector<std::pair<std::string, double>> variants;
  double seconds = 0.0;
  std::string BriefReport() const;
};

// The directional albedo of `brdf` for light from polar angle theta_i (radians), per channel: the
// integral of f cos(theta_o) over the exitant hemisphere (midpoint rule, 48 x 96 cells in (cos^2 theta_o,
// phi_o)), and its maximum over theta_i in 0 to 89.5 degrees (40 angles).
Eigen::Vector3d DirectionalAlbedo(const BrdfModel& brdf, double theta_i);
Eigen::Vector3d MaxDirectionalAlbedoPerChannel(const BrdfModel& brdf);
double MaxDirectionalAlbedo(const BrdfModel& brdf);

// Fits each colour channel separately with `lafortune_lobes` lobes from several starting points.
ModelFitResult FitLafortune(const std::vector<BrdfSample>& samples, const ModelFitOptions& options);
// Fits diffuse albedo and specular F0 per channel and one GGX alpha, twice: with the dielectric Fresnel
// (a specular term that vanishes with F0 = 0) and with Schlick's per channel (a conductor's); keeps
// the variant with the lower relative RMS against the samples and says so (variant, variants).
ModelFitResult FitGgx(const std::vector<BrdfSample>& samples, const ModelFitOptions& options);

// The fit as summary JSON: model, error, samples, starts, time, parameters at a bound, plausibility
// (albedo and its bound, the retro-reflection ratio, what the bounds hold, why a fit is implausible).
nlohmann::json ToJson(const ModelFitResult& fit);

// The material file of a fit, with name, description (how and from what it was fitted) and
// "colour_space": the samples' (their sidecar's "colour_space"; "unknown ..." when empty), which the
// fitted values are in; with `relative_scale` (samples measured under lights of relative intensity)
// "scale": "relative", which lets the material's reflectances exceed 1 (core/brdf_model.h).
nlohmann::json FitMaterialJson(const ModelFitResult& fit, const std::string& name, const std::string& colour_space = "",
                               bool relative_scale = false);

// Renderer materials for a GGX fit, named `name`: a metal (F0 above 0.2 with a diffuse albedo under a
// tenth of it) as a rough conductor keeping its colour (pbrt-v4 "conductor" with "reflectance", Mitsuba
// 3 "roughconductor" with eta = 1 and k from F0); anything else as the expectation of a diffuse and a
// rough conductor whose sum is the fitted one (PbrtMixFromGgx): for pbrt-v4 a "mix" of a "diffuse" and a
// "conductor", for Mitsuba 3 a "twosided" "blendbsdf" of a "diffuse" and a "roughconductor" with the
// same parameters (blendbsdf's weight, the second BSDF's share, is the mix's amount). `colour_space` is
// the samples' (their sidecar's "colour_space"), stated in both snippets, with a warning where it is not
// linear sRGB (renderers read "rgb" values as linear sRGB).
struct RendererSnippets {
  std::string kind;                     // "conductor" or "mix"
  std::string pbrt, mitsuba;            // the snippets' text
  std::string pbrt_file, mitsuba_file;  // suggested file names: NAME.pbrt, NAME.xml
};
RendererSnippets RendererMaterials(const ModelFitResult& ggx_fit, const std::string& name,
                                   const std::string& colour_space = "");

// pbrt-v4's MixMaterial picks its second material with probability `amount` at each shading point, so
// its rendered BRDF is the expectation (1 - amount) f_diffuse + amount f_conductor; Mitsuba 3's blendbsdf
// evaluates that same sum with weight = amount. For a GGX fit f = d / pi + F(cos_d) D G / (4 cos_i cos_o):
// a "diffuse" of reflectance d / (1 - amount) (at most 1: amount = 1 - max d) and a conductor of the
// fitted roughness whose complex IOR eta + i k per channel makes amount * FrComplex(cos_d; eta + i k)
// closest to the fitted Fresnel F (relative least squares over theta_d 0 to 70 degrees, 1-degree steps; a
// conductor's Fresnel rises to 1 at grazing, so the match is approximate where amount is small).
struct PbrtMixParameters {
  double amount = 1.0;                                    // probability of the conductor, in [0, 1]
  Eigen::Vector3d reflectance = Eigen::Vector3d::Zero();  // the diffuse material's, in [0, 1]
  Eigen::Vector3d eta = Eigen::Vector3d::Ones();          // the conductor's IOR, real part, per channel
  Eigen::Vector3d k = Eigen::Vector3d::Zero();            // and imaginary part
  double alpha = 0.1;                                     // GGX (Trowbridge-Reitz) alpha, not remapped
  // Relative RMS of amount * FrComplex against the fitted Fresnel over theta_d 0 to 70 degrees, per channel.
  Eigen::Vector3d fresnel_rel_rms = Eigen::Vector3d::Zero();
};
// `dielectric`: the fitted Fresnel is the exact dielectric one of eta(F0) (GgxFresnel::kDielectric),
// otherwise Schlick's of F0.
PbrtMixParameters PbrtMixFromGgx(const Eigen::Vector3d& diffuse_albedo, const Eigen::Vector3d& f0, double alpha,
                                 bool dielectric);
// The unpolarized Fresnel reflectance of a conductor of complex IOR eta + i k for light at cos_theta_i
// (pbrt-v4's FrComplex); with k = 0 and eta >= 1 the dielectric one.
double ComplexFresnel(double cos_theta_i, double eta, double k);

}  // namespace ibrdf
