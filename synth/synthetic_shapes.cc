#include "synth/synthetic_shapes.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/math.h"

namespace ibrdf {
namespace {

Eigen::Vector3d FromPolar(double theta, double phi) {
  return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
}
}  // namespace

// ---------------------------------------------------------------------------------------------------
// ImplicitSample

bool ImplicitSample::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, SurfaceHit* hit) const {
  const Eigen::Vector3d f = origin - center_;
  // The bounding sphere's span of the ray (Haines et al.'s closest-approach form, as for the sphere).
  const double b = f.dot(direction);
  const Eigen::Vector3d closest = f - b * direction;
  const double r2 = bounding_radius_ * bounding_radius_;
  const double discriminant = r2 - closest.squaredNorm();
  if (discriminant < 0.0) return false;
  const double half_chord = std::sqrt(discriminant);
  const double t_far = -b + half_chord;
  if (!(t_far > 0.0)) return false;
  double t = std::max(0.0, -b - half_chord);
  double value = Evaluate(f + t * direction, nullptr);
  // Inside at the start: a ray from inside sees no outer surface (the bounding sphere holds the solid,
  // so this happens only at t = 0).
  if (!(value > 0.0)) return false;
  // Sphere tracing: no surface lies within value / L of the current point. Each step is at least
  // kMinStep, so the loop ends (at most 2 R / kMinStep steps).
  while (true) {
    const double t_next = t + std::max(value / lipschitz_, kMinStep);
    if (t_next > t_far) return false;
    const double next = Evaluate(f + t_next * direction, nullptr);
    if (next <= 0.0) {
      // Bracketed: F(t) > 0 >= F(t_next). Newton from the secant point, safeguarded by bisection.
      double lo = t, hi = t_next, f_lo = value, f_hi = next;
      double x = hi - f_hi * (hi - lo) / (f_hi - f_lo);
      if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
      Eigen::Vector3d gradient;
      for (int iteration = 0; iteration < 100; ++iteration) {
        const double fx = Evaluate(f + x * direction, &gradient);
        if (fx > 0.0) {
          lo = x;
          f_lo = fx;
        } else {
          hi = x;
          f_hi = fx;
        }
        if (std::abs(fx) < 1e-15 || hi - lo < 1e-14) break;
        const double slope = gradient.dot(direction);
        double newton = slope != 0.0 ? x - fx / slope : 0.5 * (lo + hi);
        if (!(newton > lo && newton < hi)) newton = 0.5 * (lo + hi);
        x = newton;
      }
      hit->t = x;
      hit->point = origin + x * direction;
      Evaluate(f + x * direction, &gradient);
      hit->normal = gradient.normalized();
      return true;
    }
    t = t_next;
    value = next;
  }
}

bool ImplicitSample::Contains(const Eigen::Vector3d& point) const { return Evaluate(point - center_, nullptr) <= 0.0; }

Eigen::Vector3d ImplicitSample::RadialPoint(const Eigen::Vector3d& u, Eigen::Vector3d* normal) const {
  // Star-shaped about the centre: the ray from outside towards the centre meets the surface once.
  const double start = 1.5 * bounding_radius_;
  SurfaceHit hit;
  const bool found = Intersect(center_ + start * u, -u, &hit);
  IBRDF_CHECK(found) << "no surface along a ray towards the centre";
  if (normal) *normal = hit.normal;
  return hit.point;
}

// ---------------------------------------------------------------------------------------------------
// StarShapedSample

double StarShapedSample::Evaluate(const Eigen::Vector3d& local, Eigen::Vector3d* gradient) const {
  const double rho = local.norm();
  if (!(rho > 1e-12)) {  // the centre: deep inside
    if (gradient) *gradient = Eigen::Vector3d::UnitZ();
    return -Radius(Eigen::Vector3d::UnitZ(), nullptr);
  }
  const Eigen::Vector3d u = local / rho;
  Eigen::Vector3d g;
  const double r = Radius(u, gradient ? &g : nullptr);
  // grad of r(p / |p|) = (I - u u^T) grad r(u) / |p|.
  if (gradient) *gradient = u - (g - u * u.dot(g)) / rho;
  return rho - r;
}

void StarShapedSample::InitBounds() {
  const int n_theta = 360, n_phi = 720;
  double max_r = 0.0, min_r = std::numeric_limits<double>::infinity(), max_slope = 0.0;
  double lowest = std::numeric_limits<double>::infinity(), best_theta = 0.0, best_phi = 0.0;
  auto visit = [&](double theta, double phi) {
    const Eigen::Vector3d u = FromPolar(theta, phi);
    Eigen::Vector3d g;
    const double r = Radius(u, &g);
    max_r = std::max(max_r, r);
    min_r = std::min(min_r, r);
    max_slope = std::max(max_slope, (g - u * u.dot(g)).norm());
    if (r * u.z() < lowest) {
      lowest = r * u.z();
      best_theta = theta;
      best_phi = phi;
    }
  };
  for (int i = 0; i <= n_theta; ++i) {
    for (int j = 0; j < n_phi; ++j) visit(M_PI * i / n_theta, 2.0 * M_PI * j / n_phi);
  }
  // The lowest point, refined on a 100x finer grid around the best cell (error ~ r (0.005 deg)^2).
  const double d_theta = M_PI / n_theta, d_phi = 2.0 * M_PI / n_phi;
  const double theta0 = best_theta, phi0 = best_phi;
  for (int i = -100; i <= 100; ++i) {
    for (int j = -100; j <= 100; ++j) {
      const double theta = std::clamp(theta0 + d_theta * i / 100.0, 0.0, M_PI);
      visit(theta, phi0 + d_phi * j / 100.0);
    }
  }
  IBRDF_CHECK(min_r > 0.0) << "a star-shaped sample needs r > 0 everywhere";
  bounding_radius_ = 1.001 * max_r + 1e-6;
  const double slope = 1.25 * max_slope / (0.999 * min_r);
  lipschitz_ = std::sqrt(1.0 + slope * slope);
  lowest_z_ = lowest;
}

// ---------------------------------------------------------------------------------------------------
// SquashSample

bool SquashParams::Check(std::string* why) const {
  if (!(semi_axes.minCoeff() > 0.0)) {
    *why = "squash: semi_axes must be positive";
    return false;
  }
  if (ribs < 0 || ribs > 64 || !(rib_depth >= 0.0) || !(std::abs(asymmetry) + rib_depth < 0.5)) {
    *why = "squash: need 0 <= ribs <= 64, rib_depth >= 0 and |asymmetry| + rib_depth < 0.5";
    return false;
  }
  if (!(stem_flattening >= 0.0 && stem_flattening < 0.9) || !(stem_cos > -1.0 && stem_cos < 1.0)) {
    *why = "squash: need 0 <= stem_flattening < 0.9 and -1 < stem_cos < 1";
    return false;
  }
  return true;
}

SquashSample::SquashSample(const Eigen::Vector3d& center, const SquashParams& params)
    : StarShapedSample(center), params_(params) {
  std::string why;
  if (!params.Check(&why)) ThrowError("synthetic squash", why);
  InitBounds();
}

double SquashSample::Radius(const Eigen::Vector3d& u, Eigen::Vector3d* gradient) const {
  const Eigen::Vector3d inv2 = params_.semi_axes.cwiseProduct(params_.semi_axes).cwiseInverse();
  // The ellipsoid's radial function E = (sum u_i^2 / a_i^2)^(-1/2).
  const double q = u.cwiseProduct(u).dot(inv2);
  const double e = 1.0 / std::sqrt(q);
  // Asymmetry and ribs: A = 1 + alpha u_x + beta Re(z^k), z = u_x + i u_y.
  const std::complex<double> z(u.x(), u.y());
  std::complex<double> zk1(1.0, 0.0);  // z^(k-1)
  for (int i = 1; i < params_.ribs; ++i) zk1 *= z;
  const std::complex<double> zk = params_.ribs > 0 ? zk1 * z : std::complex<double>(1.0, 0.0);
  const double beta = params_.ribs > 0 ? params_.rib_depth : 0.0;
  const double a = 1.0 + params_.asymmetry * u.x() + beta * zk.real();
  // Stem flattening: S = 1 - gamma w^2.
  const double w = std::max(0.0, (u.z() - params_.stem_cos) / (1.0 - params_.stem_cos));
  const double s = 1.0 - params_.stem_flattening * w * w;
  if (gradient) {
    const Eigen::Vector3d grad_e = -e * e * e * u.cwiseProduct(inv2);
    const double k = params_.ribs;
    const Eigen::Vector3d grad_a(params_.asymmetry + beta * k * zk1.real(), -beta * k * zk1.imag(), 0.0);
    const Eigen::Vector3d grad_s(0.0, 0.0, -2.0 * params_.stem_flattening * w / (1.0 - params_.stem_cos));
    *gradient = grad_e * a * s + e * grad_a * s + e * a * grad_s;
  }
  return e * a * s;
}

nlohmann::json SquashSample::Describe() const {
  return {{"shape", "squash"},
          {"center", ToJson(center_)},
          {"semi_axes", ToJson(params_.semi_axes)},
          {"asymmetry", params_.asymmetry},
          {"ribs", params_.ribs},
          {"rib_depth", params_.rib_depth},
          {"stem_flattening", params_.stem_flattening},
          {"stem_cos", params_.stem_cos},
          {"bounding_radius", bounding_radius_},
          {"lipschitz", lipschitz_},
          {"lowest_z", lowest_z_}};
}

// ---------------------------------------------------------------------------------------------------
// DentedSphereSample

bool DentParams::Check(std::string* why) const {
  if (!(radius > 0.0) || !(depth > 0.0 && depth < 0.9)) {
    *why = "dent: need radius > 0 and 0 < depth < 0.9";
    return false;
  }
  if (!(dent_half_angle_deg > 1.0 && dent_half_angle_deg < 90.0) || !(axis.norm() > 0.0)) {
    *why = "dent: need 1 < dent_half_angle_deg < 90 and a non-zero axis";
    return false;
  }
  return true;
}

DentedSphereSample::DentedSphereSample(const Eigen::Vector3d& center, const DentParams& params)
    : StarShapedSample(center), params_(params) {
  std::string why;
  if (!params.Check(&why)) ThrowError("synthetic dent", why);
  axis_ = params.axis.normalized();
  cos_half_angle_ = std::cos(params.dent_half_angle_deg * kDegree);
  InitBounds();
}

bool DentedSphereSample::InDent(const Eigen::Vector3d& u) const { return u.dot(axis_) > cos_half_angle_; }

double DentedSphereSample::Radius(const Eigen::Vector3d& u, Eigen::Vector3d* gradient) const {
  const double span = 1.0 - cos_half_angle_;
  const double w = std::clamp((u.dot(axis_) - cos_half_angle_) / span, 0.0, 1.0);
  const double s = w * w * (3.0 - 2.0 * w);
  if (gradient) *gradient = -params_.radius * params_.depth * 6.0 * w * (1.0 - w) / span * axis_;
  return params_.radius * (1.0 - params_.depth * s);
}

nlohmann::json DentedSphereSample::Describe() const {
  return {{"shape", "dent"},
          {"center", ToJson(center_)},
          {"radius", params_.radius},
          {"depth", params_.depth},
          {"dent_half_angle_deg", params_.dent_half_angle_deg},
          {"axis", ToJson(axis_)},
          {"bounding_radius", bounding_radius_},
          {"lipschitz", lipschitz_},
          {"lowest_z", lowest_z_}};
}

// ---------------------------------------------------------------------------------------------------
// PotSample

bool PotParams::Check(std::string* why) const {
  if (!(foot_radius > 0.0 && body_radius > foot_radius) || !(bottom_z < cone_top_z && cone_top_z < top_z) ||
      !(fillet > 0.0)) {
    *why = "pot: need 0 < foot_radius < body_radius, bottom_z < cone_top_z < top_z and fillet > 0";
    return false;
  }
  return true;
}

PotSample::PotSample(const Eigen::Vector3d& center, const PotParams& params) : ImplicitSample(center), params_(params) {
  std::string why;
  if (!params.Check(&why)) ThrowError("synthetic pot", why);
  const PotParams& p = params;
  hexagon_ = {{-p.foot_radius, p.bottom_z}, {p.foot_radius, p.bottom_z}, {p.body_radius, p.cone_top_z},
              {p.body_radius, p.top_z},     {-p.body_radius, p.top_z},   {-p.body_radius, p.cone_top_z}};
  double far = 0.0;
  for (const Eigen::Vector2d& v : hexagon_) far = std::max(far, v.norm());
  bounding_radius_ = 1.001 * (far + p.fillet) + 1e-6;
  lipschitz_ = 1.0;  // an exact signed distance
  lowest_z_ = p.bottom_z - p.fillet;
}

double PotSample::Profile(const Eigen::Vector2d& q, Eigen::Vector2d* gradient) const {
  bool inside = true;
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector2d nearest = q, best_normal = Eigen::Vector2d::UnitY();
  for (size_t i = 0; i < hexagon_.size(); ++i) {
    const Eigen::Vector2d& a = hexagon_[i];
    const Eigen::Vector2d edge = hexagon_[(i + 1) % hexagon_.size()] - a;
    const Eigen::Vector2d w = q - a;
    const double h = std::clamp(w.dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    const Eigen::Vector2d d = w - h * edge;
    const Eigen::Vector2d outward = Eigen::Vector2d(edge.y(), -edge.x()).normalized();  // counter-clockwise
    if (w.dot(outward) > 0.0) inside = false;
    if (d.squaredNorm() < best) {
      best = d.squaredNorm();
      nearest = a + h * edge;
      best_normal = outward;
    }
  }
  const double distance = std::sqrt(best);
  if (gradient) {
    if (distance > 1e-15) {
      *gradient = (inside ? -1.0 : 1.0) * (q - nearest) / distance;
    } else {
      *gradient = best_normal;
    }
  }
  return inside ? -distance : distance;
}

double PotSample::Evaluate(const Eigen::Vector3d& local, Eigen::Vector3d* gradient) const {
  const double rho = std::hypot(local.x(), local.y());
  Eigen::Vector2d g;
  const double value = Profile(Eigen::Vector2d(rho, local.z()), gradient ? &g : nullptr) - params_.fillet;
  if (gradient) {
    const Eigen::Vector2d radial =
        rho > 1e-15 ? Eigen::Vector2d(local.x() / rho, local.y() / rho) : Eigen::Vector2d::Zero();
    *gradient = Eigen::Vector3d(g.x() * radial.x(), g.x() * radial.y(), g.y());
  }
  return value;
}

nlohmann::json PotSample::Describe() const {
  return {{"shape", "pot"},
          {"center", ToJson(center_)},
          {"foot_radius", params_.foot_radius},
          {"body_radius", params_.body_radius},
          {"bottom_z", params_.bottom_z},
          {"cone_top_z", params_.cone_top_z},
          {"top_z", params_.top_z},
          {"fillet", params_.fillet},
          {"bounding_radius", bounding_radius_},
          {"lipschitz", lipschitz_},
          {"lowest_z", lowest_z_}};
}

}  // namespace ibrdf
