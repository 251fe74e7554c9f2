#include "reconstruct/model_fit.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>

#include <array>

#include <ceres/ceres.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "reconstruct/model_cost_functions.h"

namespace ibrdf {
namespace {

// A channel the sample did not measure (BrdfSample::valid 0) has an infinite sigma: it adds no
// residual (Lafortune skips it, GGX weighs it by 1 / sigma = 0) and no start value.
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
      if (!s.valid[c]) f.sigma[c] = std::numeric_limits<double>::infinity();
    }
    picked.push_back(f);
  }
  return picked;
}

// The indices 0 .. count - 1.
std::vector<size_t> AllIndices(size_t count) {
  std::vector<size_t> all(count);
  for (size_t i = 0; i < count; ++i) all[i] = i;
  return all;
}

// The samples the starts are ranked on (ModelFitOptions::start_samples): a random subset of
// `start_samples` of the indices 0 .. count - 1 (shuffled with `seed`), or all of them in order where
// start_samples is 0 or not below count (every start solved on all samples).
std::vector<size_t> StartSubset(size_t count, size_t start_samples, uint64_t seed) {
  std::vector<size_t> subset = AllIndices(count);
  if (start_samples > 0 && start_samples < count) {
    std::mt19937_64 rng(seed);
    std::shuffle(subset.begin(), subset.end(), rng);
    subset.resize(start_samples);
  }
  return subset;
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
      if (!std::isfinite(s.sigma[c])) continue;  // not measured
      const double rel = (f[c] - s.value[c]) / std::max(std::abs(s.value[c]), 1e-6);
      sum += rel * rel;
      ++count;
    }
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

// The relative RMS by band of the larger of theta_i, theta_o: 0-25, 25-50, 50-80 degrees (and beyond,
// up to the fit's theta limit, in the last band), over the channels each sample measured (an unmeasured
// channel's value is no datum).
std::vector<double> BandRelativeRms(const BrdfModel& model, const std::vector<FitSample>& samples) {
  std::vector<double> sum(3, 0.0);
  std::vector<size_t> count(3, 0);
  for (const FitSample& s : samples) {
    const double theta = std::acos(std::min(s.wi.z(), s.wo.z())) * 180.0 / M_PI;
    const size_t band = theta < 25.0 ? 0 : theta < 50.0 ? 1 : 2;
    const Eigen::Vector3d f = model.Eval(s.wi, s.wo);
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(s.sigma[c])) continue;  // not measured
      const double rel = (f[c] - s.value[c]) / std::max(std::abs(s.value[c]), 1e-6);
      sum[band] += rel * rel;
      ++count[band];
    }
  }
  std::vector<double> rms(3, 0.0);
  for (size_t b = 0; b < 3; ++b) rms[b] = count[b] ? std::sqrt(sum[b] / double(count[b])) : 0.0;
  return rms;
}

// The exitant hemisphere as rings x sectors cells of equal projected solid angle: midpoints in
// (u = cos^2 theta_o, phi_o), where cos theta_o d omega = du dphi / 2, so every cell weighs
// pi / (rings sectors) and the weights sum to pi. DirectionalAlbedo and the albedo penalty share it.
std::vector<Eigen::Vector3d> ProjectedSolidAngleCells(int rings, int sectors) {
  std::vector<Eigen::Vector3d> cells;
  cells.reserve(size_t(rings) * sectors);
  for (int r = 0; r < rings; ++r) {
    const double u = (r + 0.5) / rings;
    const double cos_o = std::sqrt(u), sin_o = std::sqrt(1.0 - u);
    for (int k = 0; k < sectors; ++k) {
      const double phi = 2.0 * M_PI * (k + 0.5) / sectors;
      cells.emplace_back(sin_o * std::cos(phi), sin_o * std::sin(phi), cos_o);
    }
  }
  return cells;
}

double ProjectedSolidAngleCellWeight(int rings, int sectors) { return M_PI / (double(rings) * sectors); }

// The albedo penalty's fixed quadrature: incidence directions (in the x-z plane: the models are
// isotropic) and 16 x 32 ProjectedSolidAngleCells, coarser than DirectionalAlbedo's 48 x 96 since
// the solver evaluates it at every step.
struct AlbedoQuadrature {
  std::vector<Eigen::Vector3d> wi, wo;
  std::vector<double> weights;
};

AlbedoQuadrature MakeAlbedoQuadrature() {
  constexpr int kRings = 16, kSectors = 32;
  AlbedoQuadrature q;
  for (double theta_deg : {0.0, 25.0, 45.0, 60.0, 70.0, 78.0, 84.0, 89.0}) {
    const double theta = theta_deg * M_PI / 180.0;
    q.wi.emplace_back(std::sin(theta), 0.0, std::cos(theta));
  }
  q.wo = ProjectedSolidAngleCells(kRings, kSectors);
  q.weights.assign(q.wo.size(), ProjectedSolidAngleCellWeight(kRings, kSectors));
  return q;
}

// A direction pair near retro-reflection that no sample constrains, its ceiling per channel
// (ModelFitOptions::max_unmeasured_ratio times `beside`, the largest sample beside it; infinite where
// none is) and its theta_h.
struct Probe {
  Eigen::Vector3d wi, wo, ceiling, beside;
  double theta_h_deg = 0.0;
};

// What a plausible fit to the samples keeps to: each channel's albedo bound and the retro-reflection
// probes.
struct PlausibilityBounds {
  Eigen::Vector3d albedo = Eigen::Vector3d::Ones();
  std::vector<Probe> probes;
  double theta_d_min = 0.0;  // the samples' smallest theta_d, radians
};

PlausibilityBounds MakePlausibilityBounds(const std::vector<FitSample>& samples, const ModelFitOptions& options) {
  PlausibilityBounds bounds;
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();
  double theta_d_min = M_PI;
  std::vector<HalfDiffAngles> angles(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    ToHalfDiff(samples[i].wi, samples[i].wo, &angles[i]);
    theta_d_min = std::min(theta_d_min, angles[i].theta_d);
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(samples[i].sigma[c])) largest[c] = std::max(largest[c], samples[i].value[c]);
    }
  }
  for (int c = 0; c < 3; ++c) {
    bounds.albedo[c] = options.relative_scale ? M_PI * largest[c] : 1.0;
    if (!(bounds.albedo[c] > 0.0)) bounds.albedo[c] = std::numeric_limits<double>::infinity();
  }
  bounds.theta_d_min = theta_d_min;
  // Retro-reflection is sampled (a camera beside the light): nothing there to bound.
  const double degree = M_PI / 180.0;
  if (theta_d_min < 1.0 * degree) return bounds;
  // The largest sample per channel in each half-degree bin of theta_h, whatever its theta_d: at the
  // same theta_h the samples of smallest theta_d alone miss a sharp lobe's peak at theta_h 0, where
  // few samples lie.
  constexpr int kBins = 180;
  std::vector<Eigen::Vector3d> beside(kBins, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3i> counted(kBins, Eigen::Vector3i::Zero());
  for (size_t i = 0; i < samples.size(); ++i) {
    const int bin = std::clamp(int(angles[i].theta_h / degree * 2.0), 0, kBins - 1);
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(samples[i].sigma[c])) continue;
      beside[bin][c] = std::max(beside[bin][c], samples[i].value[c]);
      ++counted[bin][c];
    }
  }
  const double cos_max = std::cos(options.max_theta_deg * degree);
  for (double theta_h_deg = 0.0; theta_h_deg <= options.max_theta_deg; theta_h_deg += 2.0) {
    Eigen::Vector3d largest_beside = Eigen::Vector3d::Zero();
    Eigen::Vector3i count = Eigen::Vector3i::Zero();
    const int centre = int(theta_h_deg * 2.0);
    for (int bin = std::max(0, centre - 5); bin <= std::min(kBins - 1, centre + 4); ++bin) {
      largest_beside = largest_beside.cwiseMax(beside[bin]);
      count += counted[bin];
    }
    Probe probe;
    probe.theta_h_deg = theta_h_deg;
    probe.beside = largest_beside;
    bool any = false;
    for (int c = 0; c < 3; ++c) {
      const bool known = count[c] > 0 && largest_beside[c] > 0.0;
      probe.ceiling[c] = known ? options.max_unmeasured_ratio * largest_beside[c]
                               : std::numeric_limits<double>::infinity();
      any = any || known;
    }
    if (!any) continue;
    // Exact retro-reflection and halfway to the smallest sampled theta_d, in and across the plane.
    const double theta_d[3] = {0.0, 0.5 * theta_d_min, 0.5 * theta_d_min};
    const double phi_d[3] = {0.0, 0.0, 0.5 * M_PI};
    for (int k = 0; k < 3; ++k) {
      HalfDiffAngles a;
      a.theta_h = theta_h_deg * degree;
      a.theta_d = theta_d[k];
      a.phi_d = phi_d[k];
      FromHalfDiff(a, &probe.wi, &probe.wo);
      if (!(probe.wi.z() >= cos_max && probe.wo.z() >= cos_max)) continue;
      bounds.probes.push_back(probe);
    }
  }
  return bounds;
}

// The fit's verdict against its bounds (ModelFitResult: max_albedo, albedo_bound, max_retro_ratio,
// held_by_plausibility, plausible, implausible), on the dense albedo grid and at every probe.
void JudgePlausibility(const BrdfModel& model, const PlausibilityBounds& bounds, const ModelFitOptions& options,
                       ModelFitResult* result) {
  const char* channel_names = "RGB";
  const Eigen::Vector3d albedo = MaxDirectionalAlbedoPerChannel(model);
  result->max_albedo = albedo.maxCoeff();
  result->relative_scale = options.relative_scale;
  result->albedo_bound = 0.0;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(bounds.albedo[c])) continue;
    result->albedo_bound = std::max(result->albedo_bound, bounds.albedo[c]);
    char line[160];
    if (albedo[c] > bounds.albedo[c] * (1.0 + options.plausibility_tolerance)) {
      std::snprintf(line, sizeof(line), "directional albedo %c %.3f above its bound %.3g", channel_names[c],
                    albedo[c], bounds.albedo[c]);
      result->implausible.push_back(line);
    } else if (albedo[c] >= 0.99 * bounds.albedo[c]) {
      std::snprintf(line, sizeof(line), "albedo %c at its bound %.3g", channel_names[c], bounds.albedo[c]);
      result->held_by_plausibility.push_back(line);
    }
  }
  result->max_retro_ratio = 0.0;
  result->theta_d_min_deg = bounds.theta_d_min * 180.0 / M_PI;
  result->retro_probes = bounds.probes.size();
  for (int c = 0; c < 3; ++c) {
    int held = 0, probed = 0;
    double worst_ratio = 0.0, worst_theta_h = 0.0;
    for (const Probe& probe : bounds.probes) {
      if (!std::isfinite(probe.ceiling[c])) continue;
      ++probed;
      const double f = model.Eval(probe.wi, probe.wo)[c];
      const double ratio = f / probe.beside[c];
      if (ratio > worst_ratio) worst_ratio = ratio, worst_theta_h = probe.theta_h_deg;
      if (f >= 0.98 * probe.ceiling[c]) ++held;
    }
    result->max_retro_ratio = std::max(result->max_retro_ratio, worst_ratio);
    // Beyond the samples' theta: compared with the samples beside the last probe of this channel.
    const Probe* last = nullptr;
    for (const Probe& probe : bounds.probes) {
      if (std::isfinite(probe.ceiling[c]) && (!last || probe.theta_h_deg >= last->theta_h_deg)) last = &probe;
    }
    for (double theta_deg : {85.0, 89.0}) {
      if (!last || theta_deg <= last->theta_h_deg) continue;
      const double theta = theta_deg * M_PI / 180.0;
      const Eigen::Vector3d w(std::sin(theta), 0.0, std::cos(theta));
      const double ratio = model.Eval(w, w)[c] / last->beside[c];
      if (ratio <= options.max_unmeasured_ratio) continue;
      char beyond[200];
      std::snprintf(beyond, sizeof(beyond), "retro-reflection %c at %g deg %.3g times the samples at theta_h %g deg",
                    channel_names[c], theta_deg, ratio, last->theta_h_deg);
      result->beyond_samples.push_back(beyond);
      break;
    }
    char line[200];
    if (worst_ratio > options.max_unmeasured_ratio * (1.0 + options.plausibility_tolerance)) {
      std::snprintf(line, sizeof(line),
                    "retro-reflection %c %.3g times the samples beside it at theta_h %g deg (ceiling %g times)",
                    channel_names[c], worst_ratio, worst_theta_h, options.max_unmeasured_ratio);
      result->implausible.push_back(line);
    } else if (held > 0) {
      std::snprintf(line, sizeof(line), "retro-reflection %c at its ceiling at %d of %d probes", channel_names[c],
                    held, probed);
      result->held_by_plausibility.push_back(line);
    }
  }
  result->plausible = result->implausible.empty();
}

// Penalty keeping a lobe's maximum anywhere, max(|Cxy|, |Cz|)^n, below `cap`: the excess of n log(max)
// over log(cap), weighted heavily (the data residuals are in sigmas). (The base's exact maximum is
// max(|Cxy|, Cz): a negative Cz only lowers it; counting |Cz| is conservative, and relaxing it moved
// the primer's fit to a worse minimum: docs/decisions.md, "Fit plausibility".)
template <int kLobes>
struct LobeCapPenalty {
  explicit LobeCapPenalty(double log_cap_in) : log_cap(log_cap_in) {}
  template <class T>
  bool operator()(const T* p, T* residual) const {
    for (int k = 0; k < kLobes; ++k) {
      const T cxy = p[1 + 3 * k] < T(0.0) ? -p[1 + 3 * k] : p[1 + 3 * k];
      const T cz = p[2 + 3 * k] < T(0.0) ? -p[2 + 3 * k] : p[2 + 3 * k];
      T largest = cxy > cz ? cxy : cz;
      if (largest < T(1e-6)) largest = T(1e-6);
      const T excess = p[3 + 3 * k] * log(largest) - T(log_cap);
      residual[k] = excess > T(0.0) ? T(1e3) * excess : T(0.0);
    }
    return true;
  }
  double log_cap;
};

template <int kLobes>
std::unique_ptr<LafortuneBrdf> FitLafortuneLobes(const std::vector<FitSample>& samples, const ModelFitOptions& options,
                                                 const PlausibilityBounds& bounds, double* cost, int* starts,
                                                 size_t* ranked_on, std::vector<std::string>* at_bound,
                                                 std::vector<std::string>* at_cap) {
  // Starting lobes: a forward (specular) lobe, a retro-reflective one and a broad one, in several
  // sharpnesses; every channel keeps the best of its starts. Channels and starts run in parallel.
  const double starts_table[][3][3] = {
      {{-1.0, 0.9, 30.0}, {0.8, 0.8, 10.0}, {-0.5, 0.3, 3.0}},
      {{-1.0, 0.7, 80.0}, {-0.5, 0.2, 3.0}, {0.9, 0.8, 20.0}},
      {{-0.9, 0.9, 10.0}, {0.6, 0.6, 4.0}, {-1.0, 0.6, 100.0}},
      {{0.9, -0.1, 50.0}, {-0.7, -1.0, 5.0}, {-0.3, -0.1, 3.0}},
  };
  constexpr int kStarts = sizeof(starts_table) / sizeof(starts_table[0]);
  constexpr int kParameters = 1 + 3 * kLobes;
  *starts = kStarts;
  Eigen::Vector3d minimum = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d maximum = Eigen::Vector3d::Zero();
  for (const FitSample& s : samples) {
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(s.sigma[c])) continue;  // not measured
      minimum[c] = std::min(minimum[c], s.value[c]);
      maximum[c] = std::max(maximum[c], s.value[c]);
    }
  }
  // Each channel's lobe cap (ModelFitOptions::max_lobe_ratio, min_lobe_cap, max_lobe_floor_ratio).
  Eigen::Vector3d caps;
  for (int c = 0; c < 3; ++c) {
    caps[c] = std::max(options.max_lobe_ratio * maximum[c],
                       std::min(options.min_lobe_cap, options.max_lobe_floor_ratio * maximum[c]));
  }
  // The albedo penalty's quadrature as the residual reads it: per incidence angle, each exitant point's
  // (wi.x wo.x + wi.y wo.y, wi.z wo.z).
  const AlbedoQuadrature quadrature = MakeAlbedoQuadrature();
  std::vector<std::vector<std::pair<double, double>>> xy_z(quadrature.wi.size());
  for (size_t a = 0; a < quadrature.wi.size(); ++a) {
    for (const Eigen::Vector3d& wo : quadrature.wo) {
      const Eigen::Vector3d& wi = quadrature.wi[a];
      xy_z[a].emplace_back(wi.x() * wo.x() + wi.y() * wo.y(), wi.z() * wo.z());
    }
  }
  // The albedo bound each channel's quadrature is held to: the bound itself, lowered below where the
  // dense grid finds the fit above it (the quadrature misses part of a narrow lobe).
  Eigen::Vector3d quadrature_bound = bounds.albedo;
  // One channel's solve from `p` over `fitted` (indices into `samples`); returns the final cost. A
  // `ranking` solve (a start on the subset) stops at options.start_tolerance.
  const auto solve = [&](int c, const std::vector<size_t>& fitted, double* p, bool ranking) {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::HuberLoss huber(options.huber_scale);
    ceres::Problem problem(problem_options);
    for (size_t i : fitted) {
      const FitSample& s = samples[i];
      if (!std::isfinite(s.sigma[c])) continue;  // not measured
      problem.AddResidualBlock(new LafortuneAnalyticResidual<kLobes>(s.wi, s.wo, s.value[c], s.sigma[c]), &huber, p);
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<LobeCapPenalty<kLobes>, kLobes, kParameters>(
                                 new LobeCapPenalty<kLobes>(std::log(caps[c]))),
                             nullptr, p);
    if (options.plausibility_constraints && std::isfinite(quadrature_bound[c])) {
      for (size_t a = 0; a < quadrature.wi.size(); ++a) {
        problem.AddResidualBlock(
            new LafortuneAlbedoPenalty<kLobes>(xy_z[a], quadrature.weights, quadrature_bound[c]), nullptr, p);
      }
    }
    for (const Probe& probe : bounds.probes) {
      if (!options.plausibility_constraints || !std::isfinite(probe.ceiling[c])) continue;
      problem.AddResidualBlock(new LafortuneCeilingPenalty<kLobes>(probe.wi, probe.wo, probe.ceiling[c]), nullptr, p);
    }
    problem.SetParameterLowerBound(p, 0, 0.0);
    for (int k = 0; k < kLobes; ++k) {
      for (int j = 1; j <= 2; ++j) {
        problem.SetParameterLowerBound(p, 3 * k + j, -20.0);
        problem.SetParameterUpperBound(p, 3 * k + j, 20.0);
      }
      problem.SetParameterLowerBound(p, 3 * k + 3, 0.5);
      problem.SetParameterUpperBound(p, 3 * k + 3, 2000.0);
    }
    ceres::Solver::Summary summary;
    ceres::Solver::Options solver = SolverOptions(options);
    if (ranking) solver.function_tolerance = solver.parameter_tolerance = options.start_tolerance;
    ceres::Solve(solver, &problem, &summary);
    return summary.final_cost;
  };
  // Every (channel, start) on a random subset of the samples, in parallel, to a looser tolerance: the
  // subset ranks the starts, and each channel's best is then refined on all samples (on the demo's and
  // the squash's samples this gives the same fit as every start on all samples at a third of the CPU:
  // docs/benchmarks.md, "Reconstruct").
  const std::vector<size_t> all = AllIndices(samples.size());
  const std::vector<size_t> subset = StartSubset(samples.size(), options.start_samples, options.seed + 1);
  const bool two_phase = subset.size() < all.size();
  std::array<std::array<double, kParameters>, 3 * kStarts> solutions;
  std::array<double, 3 * kStarts> costs;
  tbb::parallel_for(0, 3 * kStarts, [&](int job) {
    const int c = job / kStarts, start = job % kStarts;
    double* p = solutions[job].data();
    p[0] = std::max(0.0, 0.8 * M_PI * minimum[c]);
    for (int k = 0; k < kLobes; ++k) {
      for (int j = 0; j < 3; ++j) p[1 + 3 * k + j] = starts_table[start][k][j];
    }
    costs[job] = solve(c, subset, p, two_phase);
  });
  std::array<int, 3> winners;
  for (int c = 0; c < 3; ++c) {
    winners[c] = c * kStarts;
    for (int start = 1; start < kStarts; ++start) {
      if (costs[c * kStarts + start] < costs[winners[c]]) winners[c] = c * kStarts + start;
    }
  }
  if (two_phase) {
    tbb::parallel_for(0, 3, [&](int c) { costs[winners[c]] = solve(c, all, solutions[winners[c]].data(), false); });
    *ranked_on = subset.size();
  }
  // The model of the winners' parameters.
  const auto model_of = [&](std::vector<LafortuneLobe>* lobes, Eigen::Vector3d* diffuse) {
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    lobes->assign(kLobes, LafortuneLobe{zero, zero, zero});
    for (int c = 0; c < 3; ++c) {
      const double* p = solutions[winners[c]].data();
      (*diffuse)[c] = p[0];
      for (int k = 0; k < kLobes; ++k) {
        (*lobes)[k].cxy[c] = p[1 + 3 * k];
        (*lobes)[k].cz[c] = p[2 + 3 * k];
        (*lobes)[k].n[c] = p[3 + 3 * k];
      }
    }
  };
  // Where the dense albedo grid finds a channel above its bound, that channel's quadrature bound is
  // lowered by the ratio and the channel solved again from where it ended (at most three times).
  for (int round = 0; round < (options.plausibility_constraints ? 3 : 0); ++round) {
    std::vector<LafortuneLobe> lobes;
    Eigen::Vector3d diffuse;
    model_of(&lobes, &diffuse);
    const Eigen::Vector3d albedo = MaxDirectionalAlbedoPerChannel(LafortuneBrdf(diffuse, lobes));
    std::vector<int> again;
    for (int c = 0; c < 3; ++c) {
      if (!(albedo[c] > bounds.albedo[c])) continue;
      quadrature_bound[c] *= 0.999 * bounds.albedo[c] / albedo[c];
      again.push_back(c);
    }
    if (again.empty()) break;
    tbb::parallel_for(size_t(0), again.size(), [&](size_t j) {
      const int c = again[j];
      costs[winners[c]] = solve(c, all, solutions[winners[c]].data(), false);
    });
  }
  Eigen::Vector3d diffuse;
  std::vector<LafortuneLobe> lobes(kLobes);
  *cost = 0.0;
  const char* channel_names = "RGB";
  for (int c = 0; c < 3; ++c) {
    const int best = winners[c];
    const double* p = solutions[best].data();
    *cost += costs[best];
    diffuse[c] = p[0];
    for (int k = 0; k < kLobes; ++k) {
      lobes[k].cxy[c] = p[1 + 3 * k];
      lobes[k].cz[c] = p[2 + 3 * k];
      lobes[k].n[c] = p[3 + 3 * k];
      const auto note = [&](const char* what, double value) {
        char line[96];
        std::snprintf(line, sizeof(line), "%s lobe %d %c at %g", what, k + 1, channel_names[c], value);
        at_bound->push_back(line);
      };
      if (p[3 + 3 * k] <= 0.5 + 1e-6) note("n", 0.5);
      if (p[3 + 3 * k] >= 2000.0 - 1e-3) note("n", 2000.0);
      if (std::abs(p[1 + 3 * k]) >= 20.0 - 1e-6) note("Cxy", p[1 + 3 * k]);
      if (std::abs(p[2 + 3 * k]) >= 20.0 - 1e-6) note("Cz", p[2 + 3 * k]);
      // A lobe whose max(|Cxy|, |Cz|)^n is within 1 % of the cap: the cap, not the samples, holds it.
      const double largest = std::max(std::abs(p[1 + 3 * k]), std::abs(p[2 + 3 * k]));
      if (largest > 0.0 && p[3 + 3 * k] * std::log(largest) >= std::log(caps[c]) - 0.01) {
        char line[96];
        std::snprintf(line, sizeof(line), "lobe %d %c at %.3g /sr", k + 1, channel_names[c], caps[c]);
        at_cap->push_back(line);
      }
    }
  }
  return std::make_unique<LafortuneBrdf>(diffuse, lobes);
}

}  // namespace

bool ModelFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(lafortune_lobes, 1, 3);
  IBRDF_CHECK_OPTION_GE(max_samples, size_t(10));
  if (start_samples != 0) IBRDF_CHECK_OPTION_GE(start_samples, size_t(10));
  IBRDF_CHECK_OPTION_GT(start_tolerance, 0.0);
  IBRDF_CHECK_OPTION_GE(relative_floor, 0.0);
  IBRDF_CHECK_OPTION_GT(absolute_floor, 0.0);
  IBRDF_CHECK_OPTION_GT(huber_scale, 0.0);
  IBRDF_CHECK_OPTION_GE(max_iterations, 1);
  IBRDF_CHECK_OPTION_GT(max_theta_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_deg, 90.0);
  IBRDF_CHECK_OPTION_GE(max_lobe_ratio, 1.0);
  IBRDF_CHECK_OPTION_GT(min_lobe_cap, 0.0);
  IBRDF_CHECK_OPTION_GE(max_lobe_floor_ratio, max_lobe_ratio);
  IBRDF_CHECK_OPTION_GE(max_unmeasured_ratio, 1.0);
  IBRDF_CHECK_OPTION_GE(plausibility_tolerance, 0.0);
  return true;
}

std::string ModelFitResult::BriefReport() const {
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "%s fit: %zu samples, relative RMS %.2f %%, cost %.4g, %d starts, max directional albedo %.3f "
                "(bound %.3g%s), %.2f s",
                model.c_str(), samples_used, 100.0 * rel_rms, final_cost, starts, max_albedo, albedo_bound,
                relative_scale ? ", relative scale: pi x the largest sample, not 1" : "", seconds);
  std::string text = buffer;
  char retro[192];
  if (retro_probes > 0) {
    std::snprintf(retro, sizeof(retro),
                  "; retro-reflection (samples from theta_d %.1f deg) at most %.2f x the samples beside it (%zu probes)",
                  theta_d_min_deg, max_retro_ratio, retro_probes);
  } else {
    std::snprintf(retro, sizeof(retro), "; retro-reflection sampled (theta_d from %.1f deg): no ceiling", theta_d_min_deg);
  }
  text += retro;
  if (!plausible) {
    text += "; NOT PLAUSIBLE:";
    for (const std::string& why : implausible) text += " " + why + ";";
  }
  if (!held_by_plausibility.empty()) {
    text += "; held by a plausibility bound:";
    for (const std::string& b : held_by_plausibility) text += " " + b + ";";
  }
  if (!beyond_samples.empty()) {
    text += "; beyond the samples' theta (held by the lobe cap only):";
    for (const std::string& b : beyond_samples) text += " " + b + ";";
  }
  if (start_samples > 0) text += "; starts ranked on " + std::to_string(start_samples) + " samples, the best refined";
  if (band_rel_rms.size() == 3) {
    char bands[160];
    std::snprintf(bands, sizeof(bands), "; by max(theta_i, theta_o) 0-25 %.2f %%, 25-50 %.2f %%, 50-80 %.2f %%",
                  100.0 * band_rel_rms[0], 100.0 * band_rel_rms[1], 100.0 * band_rel_rms[2]);
    text += bands;
  }
  if (!variant.empty()) {
    text += "; Fresnel variant " + variant + " chosen by error (";
    for (size_t i = 0; i < variants.size(); ++i) {
      char item[96];
      std::snprintf(item, sizeof(item), "%s%s %.2f %%", i ? ", " : "", variants[i].first.c_str(),
                    100.0 * variants[i].second);
      text += item;
    }
    text += ")";
  }
  if (!at_bound.empty()) {
    text += "; at a bound of the fit:";
    for (const std::string& b : at_bound) text += " " + b + ";";
  }
  if (!at_lobe_cap.empty()) {
    text += "; held by the lobe cap (max(|Cxy|, |Cz|)^n at it):";
    for (const std::string& b : at_lobe_cap) text += " " + b + ";";
  }
  return text;
}

nlohmann::json ToJson(const ModelFitResult& fit) {
  nlohmann::json json = {{"model", fit.model},          {"rel_rms_vs_samples", fit.rel_rms},
                         {"samples", fit.samples_used}, {"starts", fit.starts},
                         {"at_bound", fit.at_bound},    {"max_directional_albedo", fit.max_albedo},
                         {"seconds", fit.seconds}};
  if (fit.start_samples > 0) json["starts_ranked_on_samples"] = fit.start_samples;
  if (fit.model == "lafortune") json["lobes_at_cap"] = fit.at_lobe_cap;
  json["albedo_bound"] = fit.albedo_bound;
  json["albedo_bound_kind"] = fit.relative_scale
                                  ? "relative scale: pi x the largest sample (the lights' intensity is unknown, so 1 "
                                    "means nothing)"
                                  : "1 (energy conservation)";
  json["max_retro_ratio_vs_samples_beside"] = fit.max_retro_ratio;
  json["samples_theta_d_min_deg"] = fit.theta_d_min_deg;
  json["retro_probes"] = fit.retro_probes;
  json["held_by_plausibility"] = fit.held_by_plausibility;
  json["retro_beyond_samples"] = fit.beyond_samples;
  json["plausible"] = fit.plausible;
  json["implausible_because"] = fit.implausible;
  if (fit.band_rel_rms.size() == 3) {
    json["rel_rms_by_theta_max_deg"] = {
        {"0-25", fit.band_rel_rms[0]}, {"25-50", fit.band_rel_rms[1]}, {"50-80", fit.band_rel_rms[2]}};
  }
  if (!fit.variant.empty()) {
    json["variant"] = fit.variant;
    nlohmann::json variants = nlohmann::json::object();
    for (const auto& [name, rms] : fit.variants) variants[name] = {{"rel_rms_vs_samples", rms}};
    json["variants"] = variants;
  }
  return json;
}

Eigen::Vector3d DirectionalAlbedo(const BrdfModel& brdf, double theta_i) {
  constexpr int kRings = 48, kSectors = 96;
  static const std::vector<Eigen::Vector3d> cells = ProjectedSolidAngleCells(kRings, kSectors);
  const Eigen::Vector3d wi(std::sin(theta_i), 0.0, std::cos(theta_i));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& wo : cells) sum += brdf.Eval(wi, wo);
  return sum * ProjectedSolidAngleCellWeight(kRings, kSectors);
}

Eigen::Vector3d MaxDirectionalAlbedoPerChannel(const BrdfModel& brdf) {
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();
  for (int i = 0; i < 40; ++i) {
    const double theta = (89.5 * i / 39.0) * M_PI / 180.0;
    largest = largest.cwiseMax(DirectionalAlbedo(brdf, theta));
  }
  return largest;
}

double MaxDirectionalAlbedo(const BrdfModel& brdf) { return MaxDirectionalAlbedoPerChannel(brdf).maxCoeff(); }

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
  const PlausibilityBounds bounds = MakePlausibilityBounds(picked, options);
  switch (options.lafortune_lobes) {
    case 1:
      result.brdf = FitLafortuneLobes<1>(picked, options, bounds, &result.final_cost, &result.starts,
                                         &result.start_samples, &result.at_bound, &result.at_lobe_cap);
      break;
    case 2:
      result.brdf = FitLafortuneLobes<2>(picked, options, bounds, &result.final_cost, &result.starts,
                                         &result.start_samples, &result.at_bound, &result.at_lobe_cap);
      break;
    default:
      result.brdf = FitLafortuneLobes<3>(picked, options, bounds, &result.final_cost, &result.starts,
                                         &result.start_samples, &result.at_bound, &result.at_lobe_cap);
      break;
  }
  result.rel_rms = RelativeRms(*result.brdf, picked);
  JudgePlausibility(*result.brdf, bounds, options, &result);
  result.band_rel_rms = BandRelativeRms(*result.brdf, picked);
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
  for (const FitSample& s : picked) {
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(s.sigma[c])) minimum[c] = std::min(minimum[c], s.value[c]);
    }
  }
  // Three alpha starts for each of the two Fresnel variants, all six solves in parallel (ranked on a
  // subset, like the Lafortune starts). The dielectric variant's second block is s = sqrt(F0)
  // (GgxResidual).
  const double alpha_starts[3] = {0.05, 0.2, 0.5};
  constexpr int kStarts = 3, kVariants = 2;
  std::array<std::array<double, 7>, kStarts * kVariants> solutions;
  std::array<double, kStarts * kVariants> costs;
  const PlausibilityBounds bounds = MakePlausibilityBounds(picked, options);
  const AlbedoQuadrature quadrature = MakeAlbedoQuadrature();
  // Each variant's albedo bounds of its quadrature (lowered where the dense grid finds the fit above).
  std::array<Eigen::Vector3d, 2> quadrature_bound = {bounds.albedo, bounds.albedo};
  // One variant's solve from `p` over `fitted` (indices into `picked`); a `ranking` solve (a start on
  // the subset, as the Lafortune fit's) stops at options.start_tolerance.
  const auto solve = [&](bool dielectric, const std::vector<size_t>& fitted, double* p, bool ranking) {
    double* diffuse = p;
    double* f0 = p + 3;
    double* alpha = p + 6;
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::HuberLoss huber(options.huber_scale);
    ceres::Problem problem(problem_options);
    for (size_t i : fitted) {
      const FitSample& s = picked[i];
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GgxResidual, 3, 3, 3, 1>(
                                   new GgxResidual(s.wi, s.wo, s.value, s.sigma, dielectric)),
                               &huber, diffuse, f0, alpha);
    }
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero(), one = Eigen::Vector3d::Ones();
    const std::vector<Eigen::Vector3d> no_directions;
    const std::vector<Probe> no_probes;
    for (const Eigen::Vector3d& wi : options.plausibility_constraints ? quadrature.wi : no_directions) {
      std::vector<GgxResidual> points;
      for (const Eigen::Vector3d& wo : quadrature.wo) points.emplace_back(wi, wo, zero, one, dielectric);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<GgxAlbedoPenalty, 3, 3, 3, 1>(
              new GgxAlbedoPenalty(std::move(points), quadrature.weights, quadrature_bound[dielectric ? 0 : 1])),
          nullptr, diffuse, f0, alpha);
    }
    for (const Probe& probe : options.plausibility_constraints ? bounds.probes : no_probes) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GgxCeilingPenalty, 3, 3, 3, 1>(new GgxCeilingPenalty(
                                   GgxResidual(probe.wi, probe.wo, zero, one, dielectric), probe.ceiling)),
                               nullptr, diffuse, f0, alpha);
    }
    for (int c = 0; c < 3; ++c) {
      problem.SetParameterLowerBound(diffuse, c, 0.0);
      problem.SetParameterLowerBound(f0, c, 0.0);
      problem.SetParameterUpperBound(f0, c, dielectric ? 0.99 : 1.0);
    }
    problem.SetParameterLowerBound(alpha, 0, 0.002);
    problem.SetParameterUpperBound(alpha, 0, 1.0);
    ceres::Solver::Summary summary;
    ceres::Solver::Options solver = SolverOptions(options);
    if (ranking) solver.function_tolerance = solver.parameter_tolerance = options.start_tolerance;
    ceres::Solve(solver, &problem, &summary);
    return summary.final_cost;
  };
  const std::vector<size_t> all = AllIndices(picked.size());
  const std::vector<size_t> subset = StartSubset(picked.size(), options.start_samples, options.seed + 2);
  const bool two_phase = subset.size() < all.size();
  if (two_phase) result.start_samples = subset.size();
  tbb::parallel_for(0, kStarts * kVariants, [&](int job) {
    const int start = job % kStarts;
    const bool dielectric = job / kStarts == 0;
    double* p = solutions[job].data();
    p[6] = alpha_starts[start];
    for (int c = 0; c < 3; ++c) {
      p[c] = std::max(0.0, 0.8 * M_PI * minimum[c]);
      p[3 + c] = dielectric ? 0.2 : 0.04;  // sqrt(0.04) for the dielectric
    }
    costs[job] = solve(dielectric, subset, p, two_phase);
  });
  result.starts = kStarts * kVariants;
  // The best start of each variant (refined on all samples after a ranking on the subset), then the
  // variant with the lower relative RMS.
  std::array<int, kVariants> winners;
  for (int variant = 0; variant < kVariants; ++variant) {
    winners[variant] = variant * kStarts;
    for (int job = winners[variant] + 1; job < (variant + 1) * kStarts; ++job) {
      if (costs[job] < costs[winners[variant]]) winners[variant] = job;
    }
  }
  if (two_phase) {
    tbb::parallel_for(0, kVariants, [&](int variant) {
      costs[winners[variant]] = solve(variant == 0, all, solutions[winners[variant]].data(), false);
    });
  }
  // The model of a variant's solution (the dielectric variant's second block is sqrt(F0)).
  const auto model_of = [&](int variant) {
    const double* p = solutions[winners[variant]].data();
    const bool dielectric = variant == 0;
    Eigen::Vector3d f0(p[3], p[4], p[5]);
    if (dielectric) f0 = f0.cwiseProduct(f0);
    return std::make_unique<GgxBrdf>(Eigen::Vector3d(p[0], p[1], p[2]), f0, p[6],
                                     dielectric ? GgxFresnel::kDielectric : GgxFresnel::kSchlick);
  };
  // Where the dense albedo grid finds a variant's channel above its bound, its quadrature bound is
  // lowered by the ratio and the variant solved again from where it ended (at most three times).
  tbb::parallel_for(0, kVariants, [&](int variant) {
    for (int round = 0; round < (options.plausibility_constraints ? 3 : 0); ++round) {
      const Eigen::Vector3d albedo = MaxDirectionalAlbedoPerChannel(*model_of(variant));
      bool again = false;
      for (int c = 0; c < 3; ++c) {
        if (!(albedo[c] > bounds.albedo[c])) continue;
        quadrature_bound[variant][c] *= 0.999 * bounds.albedo[c] / albedo[c];
        again = true;
      }
      if (!again) break;
      costs[winners[variant]] = solve(variant == 0, all, solutions[winners[variant]].data(), false);
    }
  });
  std::unique_ptr<BrdfModel> best_model;
  int best_job = -1;
  double best_rms = std::numeric_limits<double>::infinity();
  for (int variant = 0; variant < kVariants; ++variant) {
    const int chosen = winners[variant];
    const bool dielectric = variant == 0;
    std::unique_ptr<BrdfModel> model = model_of(variant);
    const double rms = RelativeRms(*model, picked);
    result.variants.emplace_back(dielectric ? "dielectric" : "conductor", rms);
    if (rms < best_rms) {
      best_rms = rms;
      best_job = chosen;
      best_model = std::move(model);
      result.variant = dielectric ? "dielectric" : "conductor";
    }
  }
  const double* best = solutions[best_job].data();
  const bool dielectric = result.variant == "dielectric";
  if (best[6] <= 0.002 + 1e-9) result.at_bound.push_back("alpha at 0.002");
  if (best[6] >= 1.0 - 1e-9) result.at_bound.push_back("alpha at 1");
  for (int c = 0; c < 3; ++c) {
    if (!dielectric && best[3 + c] >= 1.0 - 1e-9) result.at_bound.push_back(std::string("F0 ") + "RGB"[c] + " at 1");
    if (dielectric && best[3 + c] >= 0.99 - 1e-9) {
      result.at_bound.push_back(std::string("F0 ") + "RGB"[c] + " at 0.98 (dielectric)");
    }
  }
  result.final_cost = costs[best_job];
  result.brdf = std::move(best_model);
  result.rel_rms = best_rms;
  JudgePlausibility(*result.brdf, bounds, options, &result);
  result.band_rel_rms = BandRelativeRms(*result.brdf, picked);
  result.seconds = timer.ElapsedSeconds();
  result.success = true;
  return result;
}

nlohmann::json FitMaterialJson(const ModelFitResult& fit, const std::string& name, const std::string& colour_space,
                               bool relative_scale) {
  IBRDF_CHECK(fit.brdf != nullptr);
  nlohmann::json json = fit.brdf->ToJson();
  char description[256];
  std::snprintf(description, sizeof(description),
                "%s fit by ibrdf reconstruct to %zu samples (Ceres, Huber loss on sigma-weighted residuals); "
                "relative RMS %.2f %%",
                fit.model.c_str(), fit.samples_used, 100.0 * fit.rel_rms);
  json["name"] = name;
  json["description"] = description;
  json["colour_space"] = colour_space.empty() ? "unknown (not stated with the samples)" : colour_space;
  if (relative_scale) {
    json["scale"] = "relative";
    json["description"] = json["description"].get<std::string>() +
                          "; relative scale: the lights' common intensity was not measured, so every value is the "
                          "material's times one unknown constant";
  }
  return json;
}

namespace {
struct GgxParameters {
  Eigen::Vector3d diffuse, f0;
  double alpha = 0.0;
  std::string fresnel;  // "schlick" or "dielectric"
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
  p.fresnel = object.String("fresnel", "schlick");
  return p;
}
std::string Rgb(const Eigen::Vector3d& v, const char* separator) {
  char buffer[128];
  std::snprintf(buffer, sizeof(buffer), "%.6g%s%.6g%s%.6g", v[0], separator, v[1], separator, v[2]);
  return buffer;
}
}  // namespace

double ComplexFresnel(double cos_theta_i, double eta, double k) {
  using Complex = std::complex<double>;
  const double c = std::clamp(cos_theta_i, 0.0, 1.0);
  const Complex n(eta, k);
  const Complex sin2_t = (1.0 - c * c) / (n * n);
  const Complex cos_t = std::sqrt(1.0 - sin2_t);
  const Complex r_parl = (n * c - cos_t) / (n * c + cos_t);
  const Complex r_perp = (c - n * cos_t) / (c + n * cos_t);
  return 0.5 * (std::norm(r_parl) + std::norm(r_perp));
}

namespace {
// The (eta, k) whose amount * ComplexFresnel is closest to `target` (sampled at theta_d 0, 1, ..., 70
// degrees) in relative least squares: a log-spaced grid, then a pattern search in (log eta, k).
std::pair<Eigen::Vector2d, double> FitConductorIor(const std::vector<double>& cosines,
                                                   const std::vector<double>& target, double amount) {
  const auto cost = [&](double log_eta, double k) {
    if (k < 0.0) return std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (size_t j = 0; j < cosines.size(); ++j) {
      const double r =
          (amount * ComplexFresnel(cosines[j], std::exp(log_eta), k) - target[j]) / std::max(target[j], 1e-4);
      sum += r * r;
    }
    return sum / double(cosines.size());
  };
  double best_log_eta = 0.0, best_k = 0.0, best = cost(0.0, 0.0);  // eta 1, k 0: no reflection
  for (int i = 0; i < 60; ++i) {
    const double log_eta = std::log(0.02) + (std::log(8.0) - std::log(0.02)) * i / 59.0;
    for (int j = 0; j < 61; ++j) {
      const double k = j == 0 ? 0.0 : 0.01 * std::pow(800.0, (j - 1) / 59.0);
      const double value = cost(log_eta, k);
      if (value < best) best = value, best_log_eta = log_eta, best_k = k;
    }
  }
  for (double step = 0.05; step > 1e-6;) {
    bool improved = false;
    const double moves[4][2] = {{step, 0.0}, {-step, 0.0}, {0.0, step}, {0.0, -step}};
    for (const auto& move : moves) {
      const double value = cost(best_log_eta + move[0], best_k + move[1]);
      if (value < best) best = value, best_log_eta += move[0], best_k += move[1], improved = true;
    }
    if (!improved) step *= 0.5;
  }
  return {Eigen::Vector2d(std::exp(best_log_eta), best_k), std::sqrt(best)};
}
}  // namespace

PbrtMixParameters PbrtMixFromGgx(const Eigen::Vector3d& diffuse_albedo, const Eigen::Vector3d& f0, double alpha,
                                 bool dielectric) {
  PbrtMixParameters p;
  p.alpha = alpha;
  p.amount = std::clamp(1.0 - diffuse_albedo.maxCoeff(), 0.0, 1.0);
  if (p.amount < 1.0) p.reflectance = (diffuse_albedo / (1.0 - p.amount)).cwiseMin(1.0).cwiseMax(0.0);
  std::vector<double> cosines;
  for (int degrees = 0; degrees <= 70; ++degrees) cosines.push_back(std::cos(degrees * M_PI / 180.0));
  for (int c = 0; c < 3; ++c) {
    std::vector<double> target;
    for (double cosine : cosines) {
      target.push_back(dielectric ? DielectricFresnel(cosine, IorFromF0(f0[c]))
                                  : f0[c] + (1.0 - f0[c]) * std::pow(1.0 - cosine, 5.0));
    }
    if (p.amount <= 0.0) {  // a diffuse albedo of 1: no room for the specular term
      p.fresnel_rel_rms[c] = f0[c] > 0.0 ? 1.0 : 0.0;
      continue;
    }
    const auto [ior, rms] = FitConductorIor(cosines, target, p.amount);
    p.eta[c] = ior[0];
    p.k[c] = ior[1];
    p.fresnel_rel_rms[c] = rms;
  }
  return p;
}

namespace {
// The snippet lines stating the values' colour space (the samples'), with a warning where a renderer
// would misread them: renderers take "rgb" parameters as linear sRGB.
std::vector<std::string> ColourSpaceLines(const std::string& colour_space) {
  std::string space = colour_space.empty() ? "unknown (not stated with the samples)" : colour_space;
  for (char& c : space) {
    if (c == '\n' || c == '\r') c = ' ';  // one comment line per line
  }
  for (size_t at = space.find("--"); at != std::string::npos; at = space.find("--", at)) {
    space.replace(at, 2, "- -");  // "--" may not appear inside an XML comment
  }
  std::vector<std::string> lines = {"Colour space of the values: " + space + "."};
  if (space.rfind("linear sRGB", 0) != 0) {
    lines.push_back("WARNING: not linear sRGB, but the renderer reads rgb values as linear sRGB: colours will be");
    lines.push_back("off. Measure a colour chart with the session (ibrdf colour) to get linear sRGB samples.");
  }
  return lines;
}
}  // namespace

RendererSnippets RendererMaterials(const ModelFitResult& ggx_fit, const std::string& name,
                                   const std::string& colour_space) {
  IBRDF_CHECK(ggx_fit.brdf != nullptr);
  const GgxParameters p = ReadGgx(*ggx_fit.brdf);
  RendererSnippets out;
  out.pbrt_file = name + ".pbrt";
  out.mitsuba_file = name + ".xml";
  const bool metal = p.f0.mean() > 0.2 && p.diffuse.mean() < 0.1 * p.f0.mean();
  std::ostringstream pbrt, mitsuba;
  char header[320];
  std::snprintf(header, sizeof(header), "GGX fit by ibrdf reconstruct (relative RMS %.2f %% against %zu samples)",
                100.0 * ggx_fit.rel_rms, ggx_fit.samples_used);
  std::string colour_xml;
  for (const std::string& line : ColourSpaceLines(colour_space)) colour_xml += "<!-- " + line + " -->\n";
  if (metal) {
    out.kind = "conductor";
    // pbrt-v4's conductor with "reflectance" r uses eta = 1, k = 2 sqrt(r) / sqrt(1 - r): its Fresnel
    // is r at normal incidence and rises to 1 at grazing, as the fitted Schlick term does.
    const Eigen::Vector3d r = p.f0.cwiseMin(0.999);
    Eigen::Vector3d k;
    for (int c = 0; c < 3; ++c) k[c] = 2.0 * std::sqrt(r[c]) / std::sqrt(1.0 - r[c]);
    pbrt << "# pbrt-v4: " << header << ".\n# A conductor keeping the fitted colour (F0 = reflectance); the fitted"
         << " diffuse albedo\n# (" << Rgb(p.diffuse, " ") << ") is left out.\n";
    for (const std::string& line : ColourSpaceLines(colour_space)) pbrt << "# " << line << "\n";
    pbrt << "MakeNamedMaterial \"" << name << "\"\n"
         << "    \"string type\" \"conductor\"\n"
         << "    \"rgb reflectance\" [ " << Rgb(r, " ") << " ]\n"
         << "    \"float roughness\" " << p.alpha << "\n"
         << "    \"bool remaproughness\" false\n";
    mitsuba << "<!-- Mitsuba 3: " << header << ". A rough conductor keeping the fitted colour:\n"
            << "     eta = 1 and k = 2 sqrt(F0) / sqrt(1 - F0) give Fresnel F0 at normal incidence. -->\n"
            << colour_xml << "<bsdf type=\"roughconductor\" id=\"" << name << "\">\n"
            << "    <string name=\"distribution\" value=\"ggx\"/>\n"
            << "    <float name=\"alpha\" value=\"" << p.alpha << "\"/>\n"
            << "    <rgb name=\"eta\" value=\"1, 1, 1\"/>\n"
            << "    <rgb name=\"k\" value=\"" << Rgb(k, ", ") << "\"/>\n"
            << "</bsdf>\n";
  } else {
    out.kind = "mix";
    const PbrtMixParameters mix = PbrtMixFromGgx(p.diffuse, p.f0, p.alpha, p.fresnel == "dielectric");
    char amount[32], fresnel_rms[160];
    std::snprintf(amount, sizeof(amount), "%.6g", mix.amount);
    std::snprintf(fresnel_rms, sizeof(fresnel_rms), "%.1f %%, %.1f %%, %.1f %%", 100.0 * mix.fresnel_rel_rms[0],
                  100.0 * mix.fresnel_rel_rms[1], 100.0 * mix.fresnel_rel_rms[2]);
    pbrt << "# pbrt-v4: " << header << ".\n"
         << "# A mix: pbrt-v4 picks \"" << name << "-specular\" with probability amount at each shading point,\n"
         << "# so the rendered BRDF is (1 - amount) diffuse + amount conductor, the fitted\n"
         << "# diffuse (" << Rgb(p.diffuse, " ") << ") / pi plus its GGX specular term (alpha " << p.alpha << ", "
         << (p.fresnel == "dielectric" ? "dielectric" : "Schlick") << " Fresnel of F0 " << Rgb(p.f0, " ") << ").\n"
         << "# The conductor's eta + i k make amount x Fresnel the fitted Fresnel over 0 to 70 degrees\n"
         << "# (relative RMS " << fresnel_rms << " for R, G, B); its Fresnel rises to 1 at grazing.\n";
    for (const std::string& line : ColourSpaceLines(colour_space)) pbrt << "# " << line << "\n";
    pbrt << "MakeNamedMaterial \"" << name << "-diffuse\"\n"
         << "    \"string type\" \"diffuse\"\n"
         << "    \"rgb reflectance\" [ " << Rgb(mix.reflectance, " ") << " ]\n"
         << "MakeNamedMaterial \"" << name << "-specular\"\n"
         << "    \"string type\" \"conductor\"\n"
         << "    \"rgb eta\" [ " << Rgb(mix.eta, " ") << " ]\n"
         << "    \"rgb k\" [ " << Rgb(mix.k, " ") << " ]\n"
         << "    \"float roughness\" " << p.alpha << "\n"
         << "    \"bool remaproughness\" false\n"
         << "MakeNamedMaterial \"" << name << "\"\n"
         << "    \"string type\" \"mix\"\n"
         << "    \"string materials\" [ \"" << name << "-diffuse\" \"" << name << "-specular\" ]\n"
         << "    \"float amount\" " << amount << "\n";
    // Mitsuba 3's blendbsdf evaluates (1 - weight) f(first nested BSDF) + weight f(second), the order
    // being that of the nested elements (src/bsdfs/blendbsdf.cpp eval), so the diffuse comes first and
    // weight is the mix's amount. roughconductor's GGX uses the separable Smith G, as the fit does, and
    // the conductor Fresnel of dot(wi, h), as pbrt-v4's conductor. twosided renders both faces alike.
    mitsuba << "<!-- Mitsuba 3: " << header << ".\n"
            << "     A blend: blendbsdf renders (1 - weight) x its first BSDF + weight x its second, the fitted\n"
            << "     diffuse (" << Rgb(p.diffuse, " ") << ") / pi plus its GGX specular term (alpha " << p.alpha
            << ", " << (p.fresnel == "dielectric" ? "dielectric" : "Schlick") << " Fresnel of F0 " << Rgb(p.f0, " ")
            << ").\n"
            << "     The conductor's eta + i k make weight x Fresnel the fitted Fresnel over 0 to 70 degrees\n"
            << "     (relative RMS " << fresnel_rms << " for R, G, B); its Fresnel rises to 1 at grazing.\n"
            << "     twosided: both faces render the same. -->\n"
            << colour_xml << "<bsdf type=\"twosided\" id=\"" << name << "\">\n"
            << "    <bsdf type=\"blendbsdf\">\n"
            << "        <float name=\"weight\" value=\"" << amount << "\"/>\n"
            << "        <bsdf type=\"diffuse\" id=\"" << name << "-diffuse\">\n"
            << "            <rgb name=\"reflectance\" value=\"" << Rgb(mix.reflectance, ", ") << "\"/>\n"
            << "        </bsdf>\n"
            << "        <bsdf type=\"roughconductor\" id=\"" << name << "-specular\">\n"
            << "            <string name=\"distribution\" value=\"ggx\"/>\n"
            << "            <float name=\"alpha\" value=\"" << p.alpha << "\"/>\n"
            << "            <rgb name=\"eta\" value=\"" << Rgb(mix.eta, ", ") << "\"/>\n"
            << "            <rgb name=\"k\" value=\"" << Rgb(mix.k, ", ") << "\"/>\n"
            << "        </bsdf>\n"
            << "    </bsdf>\n"
            << "</bsdf>\n";
  }
  out.pbrt = pbrt.str();
  out.mitsuba = mitsuba.str();
  return out;
}

}  // namespace ibrdf
