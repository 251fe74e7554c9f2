// Ceres residuals of the analytic BRDF models (core/brdf_model.h) against one measured sample, weighted
// by the sample's uncertainty: r = (f_model(wi, wo) - f_measured) / sigma. Templated for automatic
// differentiation; tests check them with ceres::GradientChecker.
#pragma once

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <ceres/sized_cost_function.h>
#include <Eigen/Core>

namespace ibrdf {

// One colour channel of an N-lobe Lafortune model (Lafortune et al. 1997), parameters in one block:
// [diffuse, Cxy_1, Cz_1, n_1, ..., Cxy_N, Cz_N, n_N]; f = diffuse/pi + sum max(0, Cxy xy + Cz z)^n.
template <int kLobes>
struct LafortuneResidual {
  static constexpr int kParameters = 1 + 3 * kLobes;
  LafortuneResidual(const Eigen::Vector3d& wi_in, const Eigen::Vector3d& wo_in, double value_in, double sigma)
      : xy(wi_in.x() * wo_in.x() + wi_in.y() * wo_in.y()),
        z(wi_in.z() * wo_in.z()),
        value(value_in),
        inv_sigma(1.0 / sigma) {}

  template <class T>
  bool operator()(const T* p, T* residual) const {
    T f = p[0] / T(M_PI);
    for (int k = 0; k < kLobes; ++k) {
      const T base = p[1 + 3 * k] * xy + p[2 + 3 * k] * z;
      if (!(base > T(0.0))) continue;
      // A lobe with base > 1 and a large exponent overflows (value or derivatives) during the trust
      // region's trial steps; reporting the evaluation as failed makes Ceres shrink the step (a
      // non-finite value returned as a success would be logged as an error for every sample).
      if (p[3 + 3 * k] * log(base) > T(100.0)) return false;
      f += pow(base, p[3 + 3 * k]);
    }
    residual[0] = (f - value) * inv_sigma;
    using std::isfinite;
    return isfinite(residual[0]);
  }

  double xy, z, value, inv_sigma;
};

// The same residual with analytic derivatives (what the fit uses: about three times faster than
// automatic differentiation); tests check it against LafortuneResidual and numeric differences.
template <int kLobes>
class LafortuneAnalyticResidual : public ceres::SizedCostFunction<1, 1 + 3 * kLobes> {
 public:
  LafortuneAnalyticResidual(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, double value, double sigma)
      : xy_(wi.x() * wo.x() + wi.y() * wo.y()), z_(wi.z() * wo.z()), value_(value), inv_sigma_(1.0 / sigma) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    double f = p[0] / M_PI;
    double* j = jacobians && jacobians[0] ? jacobians[0] : nullptr;
    if (j) j[0] = inv_sigma_ / M_PI;
    for (int k = 0; k < kLobes; ++k) {
      const double base = p[1 + 3 * k] * xy_ + p[2 + 3 * k] * z_;
      const double n = p[3 + 3 * k];
      if (!(base > 0.0)) {
        if (j) j[1 + 3 * k] = j[2 + 3 * k] = j[3 + 3 * k] = 0.0;
        continue;
      }
      const double log_base = std::log(base);
      if (n * log_base > 100.0) return false;  // overflow on a trial step: Ceres shrinks the step
      const double lobe = std::exp(n * log_base);
      f += lobe;
      if (j) {
        const double d_base = n * lobe / base;
        j[1 + 3 * k] = inv_sigma_ * d_base * xy_;
        j[2 + 3 * k] = inv_sigma_ * d_base * z_;
        j[3 + 3 * k] = inv_sigma_ * lobe * log_base;
      }
    }
    residuals[0] = (f - value_) * inv_sigma_;
    return std::isfinite(residuals[0]);
  }

 private:
  double xy_, z_, value_, inv_sigma_;
};

// Plausibility penalties (ModelFitOptions, "Plausible where no camera looked" in docs/reconstruct.md):
// hinge residuals, zero while the bound holds, weighted heavily against the data residuals (which are in
// sigmas), so Ceres keeps the fit inside the bound wherever the samples allow it.
constexpr double kPlausibilityPenaltyWeight = 1e3;

// One channel of a Lafortune model's directional albedo for one incidence direction, on a fixed exitant
// quadrature (points' xy = wi.x wo.x + wi.y wo.y and z = wi.z wo.z, weights cos theta_o d omega summing
// to pi): r = weight * max(0, A / bound - 1). Analytic derivatives, as LafortuneAnalyticResidual.
template <int kLobes>
class LafortuneAlbedoPenalty : public ceres::SizedCostFunction<1, 1 + 3 * kLobes> {
 public:
  LafortuneAlbedoPenalty(std::vector<std::pair<double, double>> xy_z, std::vector<double> weights, double bound)
      : xy_z_(std::move(xy_z)), weights_(std::move(weights)), inv_bound_(1.0 / bound) {
    for (double w : weights_) weight_sum_ += w;
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    double albedo = p[0] / M_PI * weight_sum_;
    double gradient[1 + 3 * kLobes] = {weight_sum_ / M_PI};
    for (size_t q = 0; q < xy_z_.size(); ++q) {
      for (int k = 0; k < kLobes; ++k) {
        const double base = p[1 + 3 * k] * xy_z_[q].first + p[2 + 3 * k] * xy_z_[q].second;
        if (!(base > 0.0)) continue;
        const double n = p[3 + 3 * k], log_base = std::log(base);
        if (n * log_base > 100.0) return false;  // overflow on a trial step: Ceres shrinks the step
        const double lobe = weights_[q] * std::exp(n * log_base);
        albedo += lobe;
        const double d_base = n * lobe / base;
        gradient[1 + 3 * k] += d_base * xy_z_[q].first;
        gradient[2 + 3 * k] += d_base * xy_z_[q].second;
        gradient[3 + 3 * k] += lobe * log_base;
      }
    }
    const double excess = albedo * inv_bound_ - 1.0;
    residuals[0] = excess > 0.0 ? kPlausibilityPenaltyWeight * excess : 0.0;
    if (jacobians && jacobians[0]) {
      for (int j = 0; j < 1 + 3 * kLobes; ++j) {
        jacobians[0][j] = excess > 0.0 ? kPlausibilityPenaltyWeight * inv_bound_ * gradient[j] : 0.0;
      }
    }
    return std::isfinite(residuals[0]);
  }

 private:
  std::vector<std::pair<double, double>> xy_z_;
  std::vector<double> weights_;
  double weight_sum_ = 0.0;
  double inv_bound_;
};

// One channel of a Lafortune model at one direction pair no sample constrains, held below a ceiling:
// r = weight * max(0, log f - log ceiling).
template <int kLobes>
class LafortuneCeilingPenalty : public ceres::SizedCostFunction<1, 1 + 3 * kLobes> {
 public:
  LafortuneCeilingPenalty(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, double ceiling)
      : xy_(wi.x() * wo.x() + wi.y() * wo.y()), z_(wi.z() * wo.z()), log_ceiling_(std::log(ceiling)) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* p = parameters[0];
    double f = p[0] / M_PI;
    double gradient[1 + 3 * kLobes] = {1.0 / M_PI};
    for (int k = 0; k < kLobes; ++k) {
      const double base = p[1 + 3 * k] * xy_ + p[2 + 3 * k] * z_;
      if (!(base > 0.0)) continue;
      const double n = p[3 + 3 * k], log_base = std::log(base);
      if (n * log_base > 100.0) return false;
      const double lobe = std::exp(n * log_base);
      f += lobe;
      gradient[1 + 3 * k] = n * lobe / base * xy_;
      gradient[2 + 3 * k] = n * lobe / base * z_;
      gradient[3 + 3 * k] = lobe * log_base;
    }
    const double excess = std::log(std::max(f, 1e-300)) - log_ceiling_;
    residuals[0] = excess > 0.0 ? kPlausibilityPenaltyWeight * excess : 0.0;
    if (jacobians && jacobians[0]) {
      for (int j = 0; j < 1 + 3 * kLobes; ++j) {
        jacobians[0][j] = excess > 0.0 ? kPlausibilityPenaltyWeight * gradient[j] / f : 0.0;
      }
    }
    return std::isfinite(residuals[0]);
  }

 private:
  double xy_, z_, log_ceiling_;
};

// GGX microfacet model as GgxBrdf evaluates it, all three channels: parameters [diffuse_albedo r g b],
// [specular_f0 r g b], [alpha].
struct GgxResidual {
  // With `dielectric_in` the second parameter block is s = sqrt(F0) per channel and the Fresnel term the
  // exact dielectric one of eta = (1 + s) / (1 - s) (0 at s = 0; no sqrt at F0 = 0 to differentiate);
  // otherwise it is F0 with Schlick's term.
  GgxResidual(const Eigen::Vector3d& wi_in, const Eigen::Vector3d& wo_in, const Eigen::Vector3d& value_in,
              const Eigen::Vector3d& sigma, bool dielectric_in = false)
      : wi(wi_in), wo(wo_in), value(value_in), inv_sigma(sigma.cwiseInverse()), dielectric(dielectric_in) {}

  template <class T>
  bool operator()(const T* diffuse, const T* f0, const T* alpha, T* residual) const {
    const Eigen::Vector3d sum = wi + wo;
    const Eigen::Vector3d h = sum.normalized();
    const T a2 = alpha[0] * alpha[0];
    const double cos_h = h.z();
    const T denominator = T(cos_h * cos_h) * (a2 - T(1.0)) + T(1.0);
    const T d = a2 / (T(M_PI) * denominator * denominator);
    const T g = G1(a2, wi.z()) * G1(a2, wo.z());
    const double schlick = std::pow(1.0 - std::max(0.0, wi.dot(h)), 5.0);
    const T specular = d * g / T(4.0 * wi.z() * wo.z());
    const double cos_d = std::max(0.0, wi.dot(h));
    for (int c = 0; c < 3; ++c) {
      const T fresnel = dielectric ? DielectricFresnel((T(1.0) + f0[c]) / (T(1.0) - f0[c]), cos_d)
                                   : f0[c] + (T(1.0) - f0[c]) * T(schlick);
      const T f = diffuse[c] / T(M_PI) + fresnel * specular;
      residual[c] = (f - value[c]) * inv_sigma[c];
    }
    using std::isfinite;
    return isfinite(residual[0]) && isfinite(residual[1]) && isfinite(residual[2]);
  }

  template <class T>
  static T G1(const T& a2, double cos_theta) {
    return T(2.0 * cos_theta) / (T(cos_theta) + sqrt(a2 + (T(1.0) - a2) * T(cos_theta * cos_theta)));
  }

  // Walter et al. 2007, eq. 22 (as core/brdf_model.h DielectricFresnel), templated for Ceres.
  template <class T>
  static T DielectricFresnel(const T& eta, double c) {
    using std::sqrt;
    const T g = sqrt(eta * eta - T(1.0) + T(c * c));
    const T a = (g - T(c)) / (g + T(c));
    const T b = (T(c) * (g + T(c)) - T(1.0)) / (T(c) * (g - T(c)) + T(1.0));
    return T(0.5) * a * a * (T(1.0) + b * b);
  }

  Eigen::Vector3d wi, wo, value, inv_sigma;
  bool dielectric = false;
};

// The GGX model's directional albedo per channel for one incidence direction on a fixed exitant
// quadrature (the points' GgxResidual against 0 with sigma 1 is f itself; `weights` cos theta_o d omega):
// r_c = weight * max(0, A_c / bound_c - 1); an infinite bound is no bound.
struct GgxAlbedoPenalty {
  GgxAlbedoPenalty(std::vector<GgxResidual> points_in, std::vector<double> weights_in, const Eigen::Vector3d& bound)
      : points(std::move(points_in)), weights(std::move(weights_in)), inv_bound(bound.cwiseInverse()) {}

  template <class T>
  bool operator()(const T* diffuse, const T* f0, const T* alpha, T* residual) const {
    T albedo[3] = {T(0.0), T(0.0), T(0.0)};
    for (size_t q = 0; q < points.size(); ++q) {
      T f[3];
      if (!points[q](diffuse, f0, alpha, f)) return false;
      for (int c = 0; c < 3; ++c) albedo[c] += T(weights[q]) * f[c];
    }
    for (int c = 0; c < 3; ++c) {
      const T excess = albedo[c] * T(inv_bound[c]) - T(1.0);
      residual[c] = excess > T(0.0) ? T(kPlausibilityPenaltyWeight) * excess : T(0.0);
    }
    return true;
  }

  std::vector<GgxResidual> points;
  std::vector<double> weights;
  Eigen::Vector3d inv_bound;
};

// The GGX model at one direction pair no sample constrains, held below a ceiling per channel:
// r_c = weight * max(0, log f_c - log ceiling_c); an infinite ceiling is none.
struct GgxCeilingPenalty {
  GgxCeilingPenalty(const GgxResidual& point_in, const Eigen::Vector3d& ceiling) : point(point_in) {
    for (int c = 0; c < 3; ++c) log_ceiling[c] = std::log(ceiling[c]);
  }

  template <class T>
  bool operator()(const T* diffuse, const T* f0, const T* alpha, T* residual) const {
    T f[3];
    if (!point(diffuse, f0, alpha, f)) return false;
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(log_ceiling[c]) || !(f[c] > T(0.0))) {
        residual[c] = T(0.0);
        continue;
      }
      const T excess = log(f[c]) - T(log_ceiling[c]);
      residual[c] = excess > T(0.0) ? T(kPlausibilityPenaltyWeight) * excess : T(0.0);
    }
    return true;
  }

  GgxResidual point;
  Eigen::Vector3d log_ceiling;
};

}  // namespace ibrdf
