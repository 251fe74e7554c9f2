#include "align/sphere_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <ceres/ceres.h>

#include "align/cost_functions/sphere_tangent_error.h"
#include "core/error.h"

namespace ibrdf {

namespace {

// The lit limb along a radial profile (samples `step` pixels apart, outwards): the sharpest drop over
// one pixel from a lit limb to a dark background, located where the profile crosses the mid level
// between the limb pixel and the first background pixel. Position along the profile in pixels, or -1.
double LitLimbEdge(const std::vector<double>& profile, double step) {
  const int span = static_cast<int>(1.0 / step);
  int best = -1;
  double best_drop = 0.0;
  for (size_t i = 0; i + span < profile.size(); ++i) {
    const double drop = profile[i] - profile[i + span];
    if (drop > best_drop) {
      best_drop = drop;
      best = static_cast<int>(i);
    }
  }
  const int guard = static_cast<int>(2.0 / step);
  if (best < guard || best + span + guard >= static_cast<int>(profile.size())) return -1.0;
  const double inside = profile[best - guard + span / 2];
  const double outside = profile[best + span + guard];
  if (!(inside > 0.03) || !(outside < 0.1 * inside)) return -1.0;
  // A rise before the edge means something brighter than the limb lies just beyond it (a white card
  // behind the sphere): the drop found is that thing's edge, not the limb. Skip the line.
  for (int i = 0; i + span <= best; ++i) {
    if (profile[i + span] - profile[i] > 0.25 * inside) return -1.0;
  }
  // Sub-pixel: the crossing of the mid level between the two ends of the steepest drop (the limb
  // pixel and the first background pixel); the level further inside may differ from the limb's.
  const double mid = 0.5 * (profile[best] + profile[best + span]);
  for (int i = best - guard; i < best + span + guard; ++i) {
    if (profile[i] >= mid && profile[i + 1] < mid)
      return step * (i + (profile[i] - mid) / (profile[i] - profile[i + 1]));
  }
  return -1.0;
}

// The unlit limb against a brighter background: the sharpest rise over one pixel from a dark limb
// (below a tenth of the background over the whole inner part of the profile, so the dark side of a
// lit sphere and not a shadowed edge of something else) to a background that stays bright (no second
// edge: a card's edge is not a background). Position in pixels, or -1.
double UnlitLimbEdge(const std::vector<double>& profile, double step) {
  const int span = static_cast<int>(1.0 / step);
  int best = -1;
  double best_rise = 0.0;
  for (size_t i = 0; i + span < profile.size(); ++i) {
    const double rise = profile[i + span] - profile[i];
    if (rise > best_rise) {
      best_rise = rise;
      best = static_cast<int>(i);
    }
  }
  const int guard = static_cast<int>(2.0 / step);
  if (best < guard || best + span + guard >= static_cast<int>(profile.size())) return -1.0;
  const double outside = profile[best + span + guard];
  if (!(outside > 0.03)) return -1.0;
  for (int i = 0; i <= best - guard / 2; ++i) {
    if (!(profile[i] < 0.1 * outside)) return -1.0;
  }
  for (size_t i = best + span + guard; i < profile.size(); ++i) {
    if (std::abs(profile[i] - outside) > 0.25 * outside) return -1.0;
  }
  const double mid = 0.5 * (profile[best] + profile[best + span]);
  for (int i = best - guard; i < best + span + guard; ++i) {
    if (profile[i] < mid && profile[i + 1] >= mid)
      return step * (i + (mid - profile[i]) / (profile[i + 1] - profile[i]));
  }
  return -1.0;
}

// S(z) = integral of phi(u) sqrt(max(z + u, 0)) du (phi the standard normal density): a square-root
// profile seen through a Gaussian blur of unit sigma, tabulated once (z from -8 to 100 in steps of
// 0.005; beyond, its expansion sqrt(z) (1 - 1 / (8 z^2))).
double BlurredSqrt(double z) {
  constexpr double kLow = -8.0, kHigh = 100.0, kStep = 0.005;
  static const std::vector<double> table = [] {
    std::vector<double> values(static_cast<size_t>((kHigh - kLow) / kStep) + 2);
    for (size_t i = 0; i < values.size(); ++i) {
      const double zi = kLow + kStep * i;
      // Substituting w = sqrt(zi + u) removes the root's singularity: u = w^2 - zi, du = 2 w dw.
      const double w_max = std::sqrt(std::max(zi + 9.0, 0.0));
      constexpr int kNodes = 600;
      double sum = 0.0;
      for (int k = 0; k < kNodes; ++k) {
        const double w = w_max * (k + 0.5) / kNodes;
        const double u = w * w - zi;
        sum += std::exp(-0.5 * u * u) * 2.0 * w * w;
      }
      values[i] = sum * w_max / kNodes / std::sqrt(2.0 * M_PI);
    }
    return values;
  }();
  if (z <= kLow) return 0.0;
  if (z >= kHigh) return std::sqrt(z) * (1.0 - 1.0 / (8.0 * z * z));
  const double u = (z - kLow) / kStep;
  const size_t i = static_cast<size_t>(u);
  return table[i] + (u - i) * (table[i + 1] - table[i]);
}

// The limb model along a profile, blurred: columns (edge level, square root, ramp, background) at
// positions xs for the edge `edge` and the blur `sigma` (pixels), and the least-squares levels;
// returns the residuals' sum of squares (and the residuals and levels when asked).
double LimbModelResiduals(const std::vector<double>& xs, const std::vector<double>& ys, double edge, double sigma,
                          Eigen::VectorXd* residuals, Eigen::Vector4d* levels) {
  const int n = static_cast<int>(xs.size());
  Eigen::MatrixXd design(n, 4);
  const double root_sigma = std::sqrt(sigma);
  for (int i = 0; i < n; ++i) {
    const double z = (edge - xs[i]) / sigma;  // depth inside the contour, in blur sigmas
    const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
    const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
    design(i, 0) = cdf;
    design(i, 1) = root_sigma * BlurredSqrt(z);
    design(i, 2) = sigma * (z * cdf + pdf);
    design(i, 3) = 1.0 - cdf;
  }
  const Eigen::Map<const Eigen::VectorXd> y(ys.data(), n);
  const Eigen::Vector4d x = (design.transpose() * design).ldlt().solve(design.transpose() * y);
  const Eigen::VectorXd r = y - design * x;
  if (residuals) *residuals = r;
  if (levels) *levels = x;
  return x.allFinite() ? r.squaredNorm() : std::numeric_limits<double>::infinity();
}

// The limb's edge refined by its radiance profile (LimbEdgeOptions in sphere_fit.h): from the first
// guess `edge` (pixels along the profile, outwards), the profile over [edge - inside_px, edge +
// outside_px] is fitted by the limb I(d) = a + b sqrt(d) + c d at depth d inside the contour (the
// shading of any smooth BRDF near a contour is a series in sqrt(d): the normal's component towards the
// camera grows like sqrt(2 d / R)), the background as a level outside, both seen through a Gaussian
// blur of fitted sigma (the lens, the pixel's footprint, the interpolation); the levels are linear, the
// edge and the blur found by Gauss-Newton. Returns the edge in pixels along the profile, or -1 where
// the model does not hold (a lit limb whose level at the contour is not positive: the terminator
// crosses it; a blur beyond max_blur_px; no convergence; a move of more than max_shift_px).
double RefineLimbEdge(const std::vector<double>& profile, double step, double edge, bool lit,
                      const LimbEdgeOptions& options) {
  const double length = step * (profile.size() - 1);
  if (edge - options.inside_px < 0.0 || edge + options.outside_px > length) return -1.0;
  std::vector<double> xs, ys;
  for (size_t i = 0; i < profile.size(); ++i) {
    const double x = step * i;
    if (x >= edge - options.inside_px && x <= edge + options.outside_px) {
      xs.push_back(x);
      ys.push_back(profile[i]);
    }
  }
  const double first_guess = edge;
  double log_sigma = std::log(0.5);
  double lambda = 1e-3;
  Eigen::VectorXd r;
  double cost = LimbModelResiduals(xs, ys, edge, std::exp(log_sigma), &r, nullptr);
  if (!std::isfinite(cost)) return -1.0;
  bool converged = false;
  for (int iteration = 0; iteration < 50 && !converged; ++iteration) {
    // Forward differences of the projected residuals in (edge, log sigma).
    constexpr double kDelta = 1e-4;
    Eigen::VectorXd r_edge, r_sigma;
    LimbModelResiduals(xs, ys, edge + kDelta, std::exp(log_sigma), &r_edge, nullptr);
    LimbModelResiduals(xs, ys, edge, std::exp(log_sigma + kDelta), &r_sigma, nullptr);
    Eigen::MatrixXd jacobian(r.size(), 2);
    jacobian.col(0) = (r_edge - r) / kDelta;
    jacobian.col(1) = (r_sigma - r) / kDelta;
    const Eigen::Matrix2d jtj = jacobian.transpose() * jacobian;
    const Eigen::Vector2d jtr = jacobian.transpose() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix2d damped = jtj;
      damped.diagonal() *= 1.0 + lambda;
      Eigen::Vector2d move = -damped.ldlt().solve(jtr);
      if (!move.allFinite()) return -1.0;
      move = move.cwiseMax(-0.5).cwiseMin(0.5);
      const double trial_log_sigma = std::clamp(log_sigma + move[1], std::log(0.05), std::log(options.max_blur_px));
      Eigen::VectorXd trial_r;
      const double trial = LimbModelResiduals(xs, ys, edge + move[0], std::exp(trial_log_sigma), &trial_r, nullptr);
      if (trial <= cost) {
        converged = std::abs(move[0]) < 1e-5 && std::abs(trial_log_sigma - log_sigma) < 1e-4;
        edge += move[0];
        log_sigma = trial_log_sigma;
        r = trial_r;
        cost = trial;
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) converged = true;  // no descent left: a minimum to the step's precision
    if (std::abs(edge - first_guess) > options.max_shift_px) return -1.0;
  }
  if (!converged) return -1.0;
  if (!(std::exp(log_sigma) < 0.99 * options.max_blur_px)) return -1.0;
  Eigen::Vector4d levels;
  LimbModelResiduals(xs, ys, edge, std::exp(log_sigma), nullptr, &levels);
  // A lit limb whose level at the contour is not above zero: the terminator crosses the limb there (the
  // shading's clamp is not in the model) and the contour has no contrast.
  if (lit && !(levels[0] > 0.0)) return -1.0;
  return edge;
}

// The unit vector from the closest point of `ray` to `center`: the derivative of the ray's distance to
// the centre with respect to the centre (minus the limb's outward normal at the tangent point).
Eigen::Vector3d TowardsCenter(const TangentRay& ray, const Eigen::Vector3d& center) {
  const Eigen::Vector3d v = center - ray.origin;
  const Eigen::Vector3d perp = v - v.dot(ray.direction) * ray.direction;
  const double norm = perp.norm();
  return norm > 0.0 ? Eigen::Vector3d(perp / norm) : Eigen::Vector3d::Zero();
}

// Covariance, limb balance, amplification and the one-sided warning of a fit over the kept rays.
void DescribeUncertainty(const std::vector<TangentRay>& rays, const std::vector<bool>& keep,
                         const SphereFitOptions& options, SphereFit* fit) {
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t k = 0; k < rays.size(); ++k) {
    if (!keep[k]) continue;
    const Eigen::Vector3d u = TowardsCenter(rays[k], fit->center);
    Eigen::Vector4d row;
    row << u, -1.0;
    information += row * row.transpose();
    mean += u;
    ++count;
  }
  if (count == 0) return;
  mean /= count;
  fit->limb_balance = mean.norm();
  const int parameters = fit->radius_fixed ? 3 : 4;
  const double variance = fit->rms_m * fit->rms_m * count / std::max(count - parameters, 1);
  fit->covariance.setZero();
  if (fit->radius_fixed) {
    fit->covariance.topLeftCorner<3, 3>() = variance * information.topLeftCorner<3, 3>().inverse();
  } else {
    fit->covariance = variance * information.inverse();
  }
  // The free radius's variance per ray, in units of the residual variance (1: all around).
  const Eigen::Matrix3d s = information.topLeftCorner<3, 3>() / count;
  const double schur = 1.0 - mean.dot(s.ldlt().solve(mean));
  fit->radius_amplification = schur > 1e-12 ? 1.0 / std::sqrt(schur) : std::numeric_limits<double>::infinity();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(fit->covariance.topLeftCorner<3, 3>());
  fit->drift_direction = eigen.eigenvectors().col(2);
  if (fit->drift_direction.dot(mean) > 0.0) fit->drift_direction = -fit->drift_direction;
  fit->one_sided = !fit->radius_fixed && (!(fit->limb_balance <= options.max_limb_balance) ||
                                          !(fit->radius_amplification <= options.max_radius_amplification));
  if (fit->one_sided) {
    char buffer[512];
    std::snprintf(buffer, sizeof(buffer),
                  "one-sided limb evidence: the silhouette points cover one side of the sphere (balance %.2f; "
                  "0 is all round), so a bias of the lit limb moves its centre and radius together, unseen "
                  "by the noise figures (radius %.1fx worse determined than from both limbs, sigma %.3f mm; "
                  "centre sigma %.3f mm along (%.2f, %.2f, %.2f)); state the known radius (sample.radius with "
                  "\"radius_known\": true) or show the unlit limb against a brighter background",
                  fit->limb_balance, fit->radius_amplification, 1e3 * std::sqrt(fit->covariance(3, 3)),
                  1e3 * std::sqrt(eigen.eigenvalues()(2)), fit->drift_direction.x(), fit->drift_direction.y(),
                  fit->drift_direction.z());
    fit->warning = buffer;
  }
}

}  // namespace

bool SphereFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(silhouette_lines, 8);
  IBRDF_CHECK_OPTION_GT(first_band_fraction, 0.0);
  IBRDF_CHECK_OPTION_GT(second_band_px, 0.0);
  IBRDF_CHECK_OPTION_GT(final_band_px, 0.0);
  IBRDF_CHECK_OPTION_GT(cauchy_m, 0.0);
  IBRDF_CHECK_OPTION_GT(outlier_rms_factor, 0.0);
  IBRDF_CHECK_OPTION_GE(min_points, 4);
  IBRDF_CHECK_OPTION_GT(tolerance, 0.0);
  IBRDF_CHECK_OPTION_GT(max_limb_balance, 0.0);
  IBRDF_CHECK_OPTION_GE(max_radius_amplification, 1.0);
  return limb_edge.Check(why);
}

bool LimbEdgeOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(inside_px, 2.0);
  IBRDF_CHECK_OPTION_GE(outside_px, 2.0);
  IBRDF_CHECK_OPTION_GT(max_shift_px, 0.0);
  IBRDF_CHECK_OPTION_GT(max_blur_px, 0.1);
  IBRDF_CHECK_OPTION_GE(arc_px, 0.0);
  return true;
}

std::string SphereFit::BriefReport() const {
  if (!fitted) return "sphere as given: " + reason;
  char buffer[320];
  std::snprintf(
      buffer, sizeof(buffer),
      "sphere centre (%.5f, %.5f, %.5f) m, radius %.5f m from %d silhouette points (RMS %.3f mm, %d rejected)",
      center.x(), center.y(), center.z(), radius, silhouette_points, 1e3 * rms_m, rejected_points);
  std::string report = buffer;
  if (radius_fixed) report += ", radius known";
  std::snprintf(buffer, sizeof(buffer), ", centre sigma %.3f mm",
                1e3 * std::sqrt(std::max(covariance.topLeftCorner<3, 3>().trace(), 0.0)));
  report += buffer;
  if (one_sided) report += "; WARNING: one-sided limb evidence";
  return report;
}

std::vector<Eigen::Vector2d> SilhouettePoints(const Image& image, const Camera& camera,
                                              const Rigid3d& camera_from_world, const Eigen::Vector3d& center,
                                              double radius, int lines, double band_px, const LimbEdgeOptions& edge) {
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector3d c = camera_from_world * center;
  if (!(c.z() > radius)) return points;
  const Eigen::Vector2d center_px = camera.ImageFromCamera(c);
  const double radius_px = camera.FocalX() * radius / std::sqrt(c.squaredNorm() - radius * radius);
  const double step = 0.25;
  // The first guess searches the band with 3 pixels each side for the levels; the refinement needs
  // its fit window beyond the guess (which may lie up to 3 pixels beyond the band).
  const double inner = edge.enabled ? edge.inside_px + 3.0 : 3.0;
  const double outer = edge.enabled ? edge.outside_px + 3.0 : 3.0;
  const int skip = static_cast<int>(std::round((inner - 3.0) / step));
  const int arc_samples = edge.enabled ? static_cast<int>(std::round(edge.arc_px / 0.5)) : 0;
  for (int k = 0; k < lines; ++k) {
    const double angle = 2.0 * M_PI * k / lines;
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    const double s0 = radius_px - band_px - 3.0 - step * skip, s1 = radius_px + band_px + outer;
    std::vector<double> profile(static_cast<size_t>(std::round((s1 - s0) / step)) + 1);
    for (size_t i = 0; i < profile.size(); ++i) {
      const double s = s0 + step * i;
      double sum = 0.0;
      for (int j = -arc_samples; j <= arc_samples; ++j) {
        const double a = angle + 0.5 * j / std::max(s, 1.0);
        sum += BilinearLuminance(image, center_px.x() + s * std::cos(a), center_px.y() + s * std::sin(a));
      }
      profile[i] = sum / (2 * arc_samples + 1);
    }
    if (std::any_of(profile.begin(), profile.end(), [](double v) { return !std::isfinite(v); })) continue;
    // The first guess: the band with 3 pixels each side, as the threshold edge finds it.
    const int count = static_cast<int>(std::round((2.0 * band_px + 6.0) / step)) + 1;
    if (skip + count > static_cast<int>(profile.size())) continue;
    const std::vector<double> band(profile.begin() + skip, profile.begin() + skip + count);
    bool lit = true;
    double guess = LitLimbEdge(band, step);
    if (guess < 0.0) {
      lit = false;
      guess = UnlitLimbEdge(band, step);
    }
    if (guess < 0.0) continue;
    double position = guess + step * skip;
    if (edge.enabled) {
      position = RefineLimbEdge(profile, step, position, lit, edge);
      if (position < 0.0) continue;
    }
    points.push_back(center_px + (s0 + position) * direction);
  }
  return points;
}

TangentRay RayThroughPixel(const Camera& camera, const Rigid3d& camera_from_world, const Eigen::Vector2d& p) {
  const Rigid3d world_from_camera = camera_from_world.Inverse();
  const Eigen::Vector2d xy = camera.CamPlaneFromImage(p);
  return {world_from_camera.translation,
          world_from_camera.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized()};
}

SphereFit FitSphereToTangentRays(const std::vector<TangentRay>& rays, const Eigen::Vector3d& start_center,
                                 double start_radius, bool reject_outliers, const SphereFitOptions& options) {
  SphereFit fit;
  fit.center = start_center;
  fit.radius = start_radius;
  if (static_cast<int>(rays.size()) < options.min_points) {
    fit.reason =
        "only " + std::to_string(rays.size()) + " silhouette points (need " + std::to_string(options.min_points) + ")";
    return fit;
  }
  double center[3] = {start_center.x(), start_center.y(), start_center.z()};
  double radius = start_radius;
  std::vector<bool> keep(rays.size(), true);
  for (int pass = 0; pass < (reject_outliers ? 2 : 1); ++pass) {
    ceres::Problem problem;
    for (size_t k = 0; k < rays.size(); ++k) {
      if (!keep[k]) continue;
      problem.AddResidualBlock(SphereTangentError::Create(rays[k].origin, rays[k].direction),
                               new ceres::CauchyLoss(options.cauchy_m), center, &radius);
    }
    problem.SetParameterLowerBound(&radius, 0, 1e-6);
    if (options.fix_radius) problem.SetParameterBlockConstant(&radius);
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.max_num_iterations = 100;
    solver_options.function_tolerance = options.tolerance;
    solver_options.parameter_tolerance = options.tolerance;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    std::vector<double> residuals(rays.size());
    double squared = 0.0;
    int count = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
      SphereTangentError(rays[k].origin, rays[k].direction)(center, &radius, &residuals[k]);
      if (keep[k]) {
        squared += residuals[k] * residuals[k];
        ++count;
      }
    }
    fit.rms_m = std::sqrt(squared / std::max(count, 1));
    fit.silhouette_points = count;
    fit.rejected_points = static_cast<int>(rays.size()) - count;
    if (pass == 0 && reject_outliers) {
      for (size_t k = 0; k < rays.size(); ++k) {
        keep[k] = std::abs(residuals[k]) <= options.outlier_rms_factor * fit.rms_m;
      }
    }
  }
  fit.center = Eigen::Vector3d(center[0], center[1], center[2]);
  fit.radius = radius;
  fit.radius_fixed = options.fix_radius;
  fit.fitted = fit.silhouette_points >= options.min_points;
  if (fit.fitted) DescribeUncertainty(rays, keep, options, &fit);
  if (!fit.fitted) {
    fit.reason = "only " + std::to_string(fit.silhouette_points) + " silhouette points left after rejecting " +
                 std::to_string(fit.rejected_points) + " outliers (need " + std::to_string(options.min_points) + ")";
  }
  return fit;
}

SphereFit FitSphereToSilhouettes(const Camera& camera, const std::vector<SilhouettePhoto>& photos,
                                 const Eigen::Vector3d& center, double radius, const SphereFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("sphere fit options", why);
  SphereFit fit;
  fit.center = center;
  fit.radius = radius;
  fit.reason = "no round ran";
  const double bands_px[] = {options.first_band_fraction, options.second_band_px, options.final_band_px};
  for (int round = 0; round < 3; ++round) {
    std::vector<TangentRay> rays;
    for (const SilhouettePhoto& photo : photos) {
      IBRDF_CHECK(photo.image != nullptr);
      const Rigid3d& pose = photo.camera_from_world;
      const Eigen::Vector3d c = pose * fit.center;
      const double radius_px =
          camera.FocalX() * fit.radius / std::sqrt(std::max(c.squaredNorm() - fit.radius * fit.radius, 1e-12));
      const double band = round == 0 ? bands_px[0] * radius_px : bands_px[round];
      for (const Eigen::Vector2d& p : SilhouettePoints(*photo.image, camera, pose, fit.center, fit.radius,
                                                       options.silhouette_lines, band, options.limb_edge)) {
        rays.push_back(RayThroughPixel(camera, pose, p));
      }
    }
    if (static_cast<int>(rays.size()) < options.min_points) {
      // The estimate of the rounds before stands (none: not fitted).
      if (round == 0) {
        fit.reason = "only " + std::to_string(rays.size()) + " silhouette points found in " +
                     std::to_string(photos.size()) + " photos (need " + std::to_string(options.min_points) + ")";
      }
      break;
    }
    fit = FitSphereToTangentRays(rays, fit.center, fit.radius, round == 2, options);
  }
  return fit;
}

}  // namespace ibrdf
