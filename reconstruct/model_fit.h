// Analytic model fits of measured samples with Ceres (the paper fits a multi-lobe Lafortune model for
// rendering, section 5): a robust (Huber) loss on residuals weighted by each sample's uncertainty, the
// sample file's sigma column with a floor. Parameters come out as a material file (samples/materials
// format, so `ibrdf synth --material` renders the fit) and, for the microfacet fit, as material
// snippets for pbrt-v4 and Mitsuba 3.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/brdf_model.h"
#include "core/sample_file.h"

namespace ibrdf {

struct ModelFitOptions {
  int lafortune_lobes = 3;       // 1 to 3 lobes
  size_t max_samples = 40000;    // a random subset (fixed seed) of at most this many samples is fitted
  double relative_floor = 0.01;  // sigma is at least this fraction of the value (noise-free samples)
  double absolute_floor = 1e-4;  // and at least this (1/sr)
  double huber_scale = 3.0;      // Huber loss threshold, in sigmas
  int max_iterations = 200;      // per Ceres solve
  double max_theta_deg = 80.0;   // samples beyond this theta_i or theta_e are left out
  uint64_t seed = 1;
  bool Check(std::string* why) const;
};

struct ModelFitResult {
  bool success = false;
  std::string model;  // "lafortune" or "ggx"
  std::unique_ptr<BrdfModel> brdf;
  size_t samples_used = 0;
  double final_cost = 0.0;  // Ceres cost, summed over the channel fits
  double rel_rms = 0.0;     // RMS of (f_fit - f) / f over the samples used and channels
  int starts = 0;           // initial guesses tried (the best is kept)
  double seconds = 0.0;
  std::string BriefReport() const;
};

// Fits each colour channel separately with `lafortune_lobes` lobes from several starting points.
ModelFitResult FitLafortune(const std::vector<BrdfSample>& samples, const ModelFitOptions& options);
// Fits diffuse albedo and specular F0 per channel and one GGX alpha.
ModelFitResult FitGgx(const std::vector<BrdfSample>& samples, const ModelFitOptions& options);

// The material file of a fit, with name and description (how and from what it was fitted).
nlohmann::json FitMaterialJson(const ModelFitResult& fit, const std::string& name);

// Material snippets for the GGX fit (their analytic microfacet materials; see docs/reconstruct.md for
// what is approximate: one scalar IOR from the mean F0, and a dielectric coating over the diffuse base).
std::string PbrtV4Material(const BrdfModel& ggx, const std::string& name);
std::string Mitsuba3Material(const BrdfModel& ggx, const std::string& name);

}  // namespace ibrdf
