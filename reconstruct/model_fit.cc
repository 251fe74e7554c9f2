#include "reconstruct/model_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include <ceres/ceres.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "reconstruct/model_cost_functions.h"

namespace ibrdf {
namespace {

struct FitSample {
  Eigen::Vector3d wi, wo, value, sigma;
};

std::vector<FitSample> PickSamples(const std::vector<BrdfSample>& samples, const ModelFitOptions& options) {
  const double max_theta = options.max_theta_deg * M_PI / 180.0;
  std::vector<size_t> eligible;
  for (size_t i = 0; i < samples.size(); ++i) {
    const BrdfSample& s = samples[i];
    if (!(s.theta_i <= max_theta && s.theta_e <= max_theta)) continue;
    if (!std::isfinite(s.brdf[0]) || !std::isfinite(s.brdf[1]) || !std::isfinite(s.brdf[2])) continue;
    eligible.push_back(i);
  }
  std::mt19937_64 rng(options.seed);
  if (eligible.size() > options.max_samples) {
    std::shuffle(eligible.begin(), eligible.end(), rng);
    eligible.resize(options.max_samples);
  }
  std::vector<FitSample> picked;
  for (size_t i : eligible) {
    const BrdfSample& s = samples[i];
    FitSample f;
    f.wi = Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized();
    f.wo = Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized();
    if (!(f.wi.z() > 0.0 && f.wo.z() > 0.0)) continue;
    for (int c = 0; c < 3; ++c) {
      f.value[c] = s.brdf[c];
      f.sigma[c] =
          std::max({double(s.sigma[c]), options.relative_floor * std::abs(f.value[c]), options.absolute_floor});
    }
    picked.push_back(f);
  }
  return picked;
}

ceres::Solver::Options SolverOptions(const ModelFitOptions& options) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.function_tolerance = 1e-10;
  solver.parameter_tolerance = 1e-10;
  solver.logging_type = ceres::SILENT;
  return solver;
}

double RelativeRms(const BrdfModel& model, const std::vector<FitSample>& samples) {
  double sum = 0.0;
  size_t count = 0;
  for (const FitSample& s : samples) {
    const Eigen::Vector3d f = model.Eval(s.wi, s.wo);
    for (int c = 0; c < 3; ++c) {
      const double rel = (f[c] - s.value[c]) / std::max(std::abs(s.value[c]), 1e-6);
      sum += rel * rel;
      ++count;
    }
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

// One channel's Lafortune fit from one start; returns the final cost.
template <int kLobes>
double SolveLafortuneChannel(const std::vector<FitSample>& samples, int channel, const ModelFitOptions& options,
                             double* parameters) {
  using Residual = LafortuneResidual<kLobes>;
  ceres::Problem problem;
  for (const FitSample& s : samples) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Residual, 1, Residual::kParameters>(
                                 new Residual(s.wi, s.wo, s.value[channel], s.sigma[channel])),
                             new ceres::HuberLoss(options.huber_scale), parameters);
  }
  problem.SetParameterLowerBound(parameters, 0, 0.0);
  for (int k = 0; k < kLobes; ++k) {
    for (int j = 1; j <= 2; ++j) {
      problem.SetParameterLowerBound(parameters, 3 * k + j, -20.0);
      problem.SetParameterUpperBound(parameters, 3 * k + j, 20.0);
    }
    problem.SetParameterLowerBound(parameters, 3 * k + 3, 0.5);
    problem.SetParameterUpperBound(parameters, 3 * k + 3, 2000.0);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(options), &problem, &summary);
  return summary.final_cost;
}

template <int kLobes>
std::unique_ptr<LafortuneBrdf> FitLafortuneLobes(const std::vector<FitSample>& samples, const ModelFitOptions& options,
                                                 double* cost, int* starts) {
  // Starting lobes: a forward (specular) lobe, a retro-reflective one and a broad one, in several
  // sharpnesses; every channel keeps the best of its starts.
  const double starts_table[][3][3] = {
      {{-1.0, 0.9, 30.0}, {0.8, 0.8, 10.0}, {-0.5, 0.3, 3.0}},
      {{-1.0, 0.7, 80.0}, {-0.5, 0.2, 3.0}, {0.9, 0.8, 20.0}},
      {{-0.9, 0.9, 10.0}, {0.6, 0.6, 4.0}, {-1.0, 0.6, 100.0}},
      {{0.9, -0.1, 50.0}, {-0.7, -1.0, 5.0}, {-0.3, -0.1, 3.0}},
  };
  constexpr int kStarts = sizeof(starts_table) / sizeof(starts_table[0]);
  *starts = kStarts;
  Eigen::Vector3d diffuse;
  std::vector<LafortuneLobe> lobes(kLobes);
  *cost = 0.0;
  for (int c = 0; c < 3; ++c) {
    double minimum = std::numeric_limits<double>::infinity();
    for (const FitSample& s : samples) minimum = std::min(minimum, s.value[c]);
    double best_cost = std::numeric_limits<double>::infinity();
    double best[1 + 3 * kLobes] = {};
    for (int start = 0; start < kStarts; ++start) {
      double p[1 + 3 * kLobes];
      p[0] = std::max(0.0, 0.8 * M_PI * minimum);
      for (int k = 0; k < kLobes; ++k) {
        for (int j = 0; j < 3; ++j) p[1 + 3 * k + j] = starts_table[start][k][j];
      }
      const double start_cost = SolveLafortuneChannel<kLobes>(samples, c, options, p);
      if (start_cost < best_cost) {
        best_cost = start_cost;
        std::copy(p, p + 1 + 3 * kLobes, best);
      }
    }
    *cost += best_cost;
    diffuse[c] = best[0];
    for (int k = 0; k < kLobes; ++k) {
      lobes[k].cxy[c] = best[1 + 3 * k];
      lobes[k].cz[c] = best[2 + 3 * k];
      lobes[k].n[c] = best[3 + 3 * k];
    }
  }
  return std::make_unique<LafortuneBrdf>(diffuse, lobes);
}

}  // namespace

bool ModelFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(lafortune_lobes, 1, 3);
  IBRDF_CHECK_OPTION_GE(max_samples, size_t(10));
  IBRDF_CHECK_OPTION_GE(relative_floor, 0.0);
  IBRDF_CHECK_OPTION_GT(absolute_floor, 0.0);
  IBRDF_CHECK_OPTION_GT(huber_scale, 0.0);
  IBRDF_CHECK_OPTION_GE(max_iterations, 1);
  IBRDF_CHECK_OPTION_GT(max_theta_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_deg, 90.0);
  return true;
}

std::string ModelFitResult::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "%s fit: %zu samples, relative RMS %.2f %%, cost %.4g, %d starts, %.2f s",
                model.c_str(), samples_used, 100.0 * rel_rms, final_cost, starts, seconds);
  return buffer;
}

ModelFitResult FitLafortune(const std::vector<BrdfSample>& samples, const ModelFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("model fit options", why);
  Timer timer;
  ModelFitResult result;
  result.model = "lafortune";
  const std::vector<FitSample> picked = PickSamples(samples, options);
  result.samples_used = picked.size();
  if (picked.size() < size_t(1 + 3 * options.lafortune_lobes)) {
    ThrowError("lafortune fit", "only " + std::to_string(picked.size()) + " usable samples");
  }
  switch (options.lafortune_lobes) {
    case 1:
      result.brdf = FitLafortuneLobes<1>(picked, options, &result.final_cost, &result.starts);
      break;
    case 2:
      result.brdf = FitLafortuneLobes<2>(picked, options, &result.final_cost, &result.starts);
      break;
    default:
      result.brdf = FitLafortuneLobes<3>(picked, options, &result.final_cost, &result.starts);
      break;
  }
  result.rel_rms = RelativeRms(*result.brdf, picked);
  result.seconds = timer.ElapsedSeconds();
  result.success = true;
  return result;
}

ModelFitResult FitGgx(const std::vector<BrdfSample>& samples, const ModelFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("model fit options", why);
  Timer timer;
  ModelFitResult result;
  result.model = "ggx";
  const std::vector<FitSample> picked = PickSamples(samples, options);
  result.samples_used = picked.size();
  if (picked.size() < 7) ThrowError("ggx fit", "only " + std::to_string(picked.size()) + " usable samples");
  Eigen::Vector3d minimum = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  for (const FitSample& s : picked) minimum = minimum.cwiseMin(s.value);
  double best_cost = std::numeric_limits<double>::infinity();
  double best[7] = {};
  result.starts = 0;
  for (double alpha_start : {0.05, 0.2, 0.5}) {
    double diffuse[3], f0[3], alpha[1] = {alpha_start};
    for (int c = 0; c < 3; ++c) {
      diffuse[c] = std::max(0.0, 0.8 * M_PI * minimum[c]);
      f0[c] = 0.04;
    }
    ceres::Problem problem;
    for (const FitSample& s : picked) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<GgxResidual, 3, 3, 3, 1>(new GgxResidual(s.wi, s.wo, s.value, s.sigma)),
          new ceres::HuberLoss(options.huber_scale), diffuse, f0, alpha);
    }
    for (int c = 0; c < 3; ++c) {
      problem.SetParameterLowerBound(diffuse, c, 0.0);
      problem.SetParameterLowerBound(f0, c, 0.0);
      problem.SetParameterUpperBound(f0, c, 1.0);
    }
    problem.SetParameterLowerBound(alpha, 0, 0.002);
    problem.SetParameterUpperBound(alpha, 0, 1.0);
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(options), &problem, &summary);
    ++result.starts;
    if (summary.final_cost < best_cost) {
      best_cost = summary.final_cost;
      std::copy(diffuse, diffuse + 3, best);
      std::copy(f0, f0 + 3, best + 3);
      best[6] = alpha[0];
    }
  }
  result.final_cost = best_cost;
  result.brdf = std::make_unique<GgxBrdf>(Eigen::Vector3d(best[0], best[1], best[2]),
                                          Eigen::Vector3d(best[3], best[4], best[5]), best[6]);
  result.rel_rms = RelativeRms(*result.brdf, picked);
  result.seconds = timer.ElapsedSeconds();
  result.success = true;
  return result;
}

nlohmann::json FitMaterialJson(const ModelFitResult& fit, const std::string& name) {
  IBRDF_CHECK(fit.brdf != nullptr);
  nlohmann::json json = fit.brdf->ToJson();
  char description[256];
  std::snprintf(description, sizeof(description),
                "%s fit by ibrdf reconstruct to %zu samples (Ceres, Huber loss on sigma-weighted residuals); "
                "relative RMS %.2f %%",
                fit.model.c_str(), fit.samples_used, 100.0 * fit.rel_rms);
  json["name"] = name;
  json["description"] = description;
  return json;
}

namespace {
struct GgxParameters {
  Eigen::Vector3d diffuse, f0;
  double alpha = 0.0;
};
GgxParameters ReadGgx(const BrdfModel& model) {
  if (model.ModelName() != "ggx") ThrowError("material snippet", "needs a ggx model, got " + model.ModelName());
  const nlohmann::json json = model.ToJson();
  JsonObject object(json, "ggx fit");
  object.String("model");
  GgxParameters p;
  p.diffuse = object.Vector3("diffuse_albedo");
  p.f0 = object.Vector3("specular_f0");
  p.alpha = object.Number("alpha");
  return p;
}
// The real IOR with the given normal-incidence reflectance: F0 = ((eta - 1) / (eta + 1))^2.
double IorFromF0(double f0) {
  const double r = std::sqrt(std::clamp(f0, 0.0, 0.99));
  return (1.0 + r) / (1.0 - r);
}
}  // namespace

std::string PbrtV4Material(const BrdfModel& ggx, const std::string& name) {
  const GgxParameters p = ReadGgx(ggx);
  std::ostringstream out;
  out << "# pbrt-v4: GGX fit by ibrdf reconstruct. Approximate: pbrt's coateddiffuse layers a dielectric\n"
      << "# (one IOR from the mean F0, exact Fresnel instead of Schlick) over a Lambertian base and\n"
      << "# simulates inter-reflection, so it is close to, not identical with, the fitted sum.\n"
      << "MakeNamedMaterial \"" << name << "\"\n"
      << "    \"string type\" \"coateddiffuse\"\n"
      << "    \"rgb reflectance\" [ " << p.diffuse[0] << " " << p.diffuse[1] << " " << p.diffuse[2] << " ]\n"
      << "    \"float roughness\" " << p.alpha << "\n"
      << "    \"bool remaproughness\" false\n"
      << "    \"float eta\" " << IorFromF0(p.f0.mean()) << "\n";
  return out.str();
}

std::string Mitsuba3Material(const BrdfModel& ggx, const std::string& name) {
  const GgxParameters p = ReadGgx(ggx);
  std::ostringstream out;
  out << "<!-- Mitsuba 3: GGX fit by ibrdf reconstruct. Approximate: roughplastic uses one IOR (from the\n"
      << "     mean F0) with exact dielectric Fresnel, and its diffuse term accounts for the coating. -->\n"
      << "<bsdf type=\"roughplastic\" id=\"" << name << "\">\n"
      << "    <string name=\"distribution\" value=\"ggx\"/>\n"
      << "    <float name=\"alpha\" value=\"" << p.alpha << "\"/>\n"
      << "    <float name=\"int_ior\" value=\"" << IorFromF0(p.f0.mean()) << "\"/>\n"
      << "    <float name=\"ext_ior\" value=\"1.0\"/>\n"
      << "    <rgb name=\"diffuse_reflectance\" value=\"" << p.diffuse[0] << ", " << p.diffuse[1] << ", "
      << p.diffuse[2] << "\"/>\n"
      << "</bsdf>\n";
  return out.str();
}

}  // namespace ibrdf
