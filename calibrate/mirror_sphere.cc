#include "calibrate/mirror_sphere.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/math.h"

namespace ibrdf {
namespace {

std::string Format(const char* format, double a, double b, double c = 0, double d = 0, double e = 0, double f = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c, d, e, f);
  return buffer;
}

Eigen::Vector3d RayThrough(const Camera& camera, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = camera.CamPlaneFromImage(pixel);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

// The cone's parameters: axis = normalize(p0, p1, 1), half angle p2.
Eigen::Vector3d AxisOf(const Eigen::Vector3d& p) { return Eigen::Vector3d(p[0], p[1], 1.0).normalized(); }

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Residuals (radians) and Jacobian of the cone fit at parameters p.
void ConeResiduals(const std::vector<Eigen::Vector3d>& rays, const Eigen::Vector3d& p, Eigen::VectorXd* residuals,
                   Eigen::MatrixXd* jacobian) {
  const Eigen::Vector3d g(p[0], p[1], 1.0);
  const Eigen::Vector3d a = g.normalized();
  const double g_norm = g.norm();
  residuals->resize(rays.size());
  if (jacobian) jacobian->resize(rays.size(), 3);
  for (size_t i = 0; i < rays.size(); ++i) {
    (*residuals)[i] = AngleBetween(rays[i], a) - p[2];
    if (!jacobian) continue;
    // d theta / d a = -u with u the unit tangent from a towards the ray; da/dg = (I - a a^T) / |g|.
    Eigen::Vector3d u = rays[i] - rays[i].dot(a) * a;
    const double n = u.norm();
    u = n > 0 ? Eigen::Vector3d(u / n) : Eigen::Vector3d::Zero();
    (*jacobian)(i, 0) = -u.x() / g_norm;
    (*jacobian)(i, 1) = -u.y() / g_norm;
    (*jacobian)(i, 2) = -1.0;
  }
}

// Gauss-Newton (Levenberg-damped) on the cone; returns the final parameters.
Eigen::Vector3d SolveCone(const std::vector<Eigen::Vector3d>& rays, Eigen::Vector3d p, int iterations) {
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  double lambda = 1e-6;
  ConeResiduals(rays, p, &r, &J);
  double cost = r.squaredNorm();
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Matrix3d JtJ = J.transpose() * J;
    const Eigen::Vector3d Jtr = J.transpose() * r;
    Eigen::Matrix3d damped = JtJ;
    damped.diagonal() *= 1.0 + lambda;
    const Eigen::Vector3d step = damped.ldlt().solve(-Jtr);
    const Eigen::Vector3d candidate = p + step;
    Eigen::VectorXd r2;
    ConeResiduals(rays, candidate, &r2, nullptr);
    const double cost2 = r2.squaredNorm();
    if (cost2 <= cost) {
      const bool converged = cost - cost2 <= 1e-14 * cost || step.norm() <= 1e-15 * (p.norm() + 1e-300);
      p = candidate;
      cost = cost2;
      lambda = std::max(lambda * 0.1, 1e-12);
      ConeResiduals(rays, p, &r, &J);
      if (converged) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e8) break;
    }
  }
  return p;
}

// Algebraic (Kasa) circle fit, on coordinates centred at their mean; false if degenerate.
bool FitCircle(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d* center, double* radius) {
  if (points.size() < 3) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& q : points) mean += q;
  mean /= double(points.size());
  Eigen::MatrixXd A(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d q = points[i] - mean;
    A.row(i) << q.x(), q.y(), 1.0;
    b[i] = -(q.x() * q.x() + q.y() * q.y());
  }
  const Eigen::Vector3d s = A.colPivHouseholderQr().solve(b);
  const Eigen::Vector2d c(-s[0] / 2, -s[1] / 2);
  const double r2 = c.squaredNorm() - s[2];
  if (!(r2 > 0) || !std::isfinite(r2)) return false;
  *center = c + mean;
  *radius = std::sqrt(r2);
  return true;
}

}  // namespace

PixelMask ReadPixelMask(const std::string& path, int width, int height) {
  const Image image = ReadImage(path);
  if (image.width != width || image.height != height) {
    ThrowError(path, "mask is " + std::to_string(image.width) + " x " + std::to_string(image.height) +
                         " pixels, the camera's photos are " + std::to_string(width) + " x " + std::to_string(height));
  }
  PixelMask mask;
  mask.width = width;
  mask.height = height;
  mask.usable.assign(size_t(width) * height, 0);
  size_t usable = 0;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      bool any = false;
      for (int c = 0; c < image.channels; ++c) any = any || image.at(x, y, c) > 0.0f;
      mask.usable[size_t(y) * width + x] = any ? 1 : 0;
      usable += any ? 1 : 0;
    }
  }
  if (usable == 0) ThrowError(path, "mask has no usable (non-zero) pixel");
  return mask;
}

bool SilhouetteFitOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(max_iterations, 0);
  IBRDF_CHECK_OPTION_GT(outlier_px, 0.0);
  IBRDF_CHECK_OPTION_GE(outlier_rms_factor, 1.0);
  IBRDF_CHECK_OPTION_GE(min_points, 6);
  return true;
}

Eigen::Vector3d SphereSilhouette::CenterInCamera(double radius) const { return axis * (radius / std::sin(half_angle)); }

SphereSilhouette SphereSilhouette::FromCenter(const Camera& camera, const Eigen::Vector3d& center_in_camera,
                                              double radius) {
  SphereSilhouette s;
  const double distance = center_in_camera.norm();
  if (!(center_in_camera.z() > 0) || !(distance > radius) || !(radius > 0)) {
    s.reason = "the sphere is not in front of the camera";
    return s;
  }
  s.fitted = true;
  s.axis = center_in_camera / distance;
  s.half_angle = std::asin(radius / distance);
  s.center_px = camera.ImageFromCamera(s.axis);
  const Eigen::Vector3d side = (Eigen::Vector3d::UnitX() - s.axis.x() * s.axis).normalized();
  s.radius_px =
      (camera.ImageFromCamera(std::cos(s.half_angle) * s.axis + std::sin(s.half_angle) * side) - s.center_px).norm();
  return s;
}

std::string SphereSilhouette::BriefReport() const {
  if (!fitted) return "silhouette: not fitted (" + reason + ")";
  return Format("silhouette: centre (%.2f, %.2f) px, radius %.2f px", center_px.x(), center_px.y(), radius_px) +
         (points > 0 ? " from " + std::to_string(points) + " edge points (" + std::to_string(rejected) +
                           " dropped, RMS " + Format("%.2f px)", rms_px, 0)
                     : std::string(" (given)"));
}

std::vector<Eigen::Vector2d> MaskEdgePoints(const PixelMask& mask) {
  std::vector<Eigen::Vector2d> points;
  for (int y = 0; y < mask.height; ++y) {
    for (int x = 0; x < mask.width; ++x) {
      const bool here = mask.at(x, y);
      // The crossing of 1/2 between two pixel centres is their shared border.
      if (x + 1 < mask.width && here != mask.at(x + 1, y)) points.emplace_back(x + 1.0, y + 0.5);
      if (y + 1 < mask.height && here != mask.at(x, y + 1)) points.emplace_back(x + 0.5, y + 1.0);
    }
  }
  return points;
}

SphereSilhouette FitSphereSilhouette(const Camera& camera, const std::vector<Eigen::Vector2d>& edge_points,
                                     const SilhouetteFitOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("silhouette fit options", why);
  SphereSilhouette fit;
  if (int(edge_points.size()) < options.min_points) {
    fit.reason = std::to_string(edge_points.size()) + " edge points, fewer than " + std::to_string(options.min_points);
    return fit;
  }
  Eigen::Vector2d center_px;
  double radius_px = 0.0;
  if (!FitCircle(edge_points, &center_px, &radius_px)) {
    fit.reason = "the edge points are not on a circle";
    return fit;
  }
  // Start: the ray through the circle's centre, the angle to the ray through its rim.
  const Eigen::Vector3d axis0 = RayThrough(camera, center_px);
  const double angle0 = AngleBetween(axis0, RayThrough(camera, center_px + Eigen::Vector2d(radius_px, 0.0)));
  Eigen::Vector3d p(axis0.x() / axis0.z(), axis0.y() / axis0.z(), angle0);

  std::vector<Eigen::Vector3d> rays;
  rays.reserve(edge_points.size());
  for (const auto& q : edge_points) rays.push_back(RayThrough(camera, q));
  // Angles to pixels, near the silhouette.
  const double px_per_rad = camera.FocalX() / std::pow(std::cos(angle0), 2);

  p = SolveCone(rays, p, options.max_iterations);
  Eigen::VectorXd r;
  ConeResiduals(rays, p, &r, nullptr);
  const double rms0 = std::sqrt(r.squaredNorm() / double(r.size())) * px_per_rad;
  const double cut = std::max(options.outlier_px, options.outlier_rms_factor * rms0);
  std::vector<Eigen::Vector3d> kept;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (std::abs(r[i]) * px_per_rad <= cut) kept.push_back(rays[i]);
  }
  if (int(kept.size()) < options.min_points) {
    fit.reason = "too few edge points agree on one circle (" + std::to_string(kept.size()) + " of " +
                 std::to_string(rays.size()) + ")";
    return fit;
  }
  p = SolveCone(kept, p, options.max_iterations);
  Eigen::MatrixXd J;
  ConeResiduals(kept, p, &r, &J);
  if (!(p[2] > 0) || !(p[2] < kPi / 2) || !r.allFinite()) {
    fit.reason = "the cone fit diverged";
    return fit;
  }
  const double variance = r.squaredNorm() / std::max<double>(1.0, double(r.size()) - 3.0);
  const Eigen::Matrix3d JtJ = J.transpose() * J;
  fit = SphereSilhouette::FromCenter(camera, AxisOf(p) * (1.0 / std::sin(p[2])), 1.0);
  fit.covariance = JtJ.inverse() * variance;
  fit.points = int(kept.size());
  fit.rejected = int(rays.size() - kept.size());
  fit.rms_px = std::sqrt(r.squaredNorm() / double(r.size())) * px_per_rad;
  return fit;
}

bool HighlightOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(blob_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(blob_fraction, 1.0);
  IBRDF_CHECK_OPTION_GT(core_fraction, blob_fraction);
  IBRDF_CHECK_OPTION_LE(core_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(rim_margin_px, 0.0);
  IBRDF_CHECK_OPTION_GE(relative_noise, 0.0);
  IBRDF_CHECK_OPTION_GE(min_sigma_px, 0.0);
  IBRDF_CHECK_OPTION_GT(max_second_peak, 0.0);
  IBRDF_CHECK_OPTION_GT(max_blob_pixels, 0);
  return true;
}

std::string Highlight::BriefReport() const {
  if (!found) return "highlight: not found (" + reason + ")";
  return Format("highlight (%.2f, %.2f) px +- %.2f px, ", pixel.x(), pixel.y(), sigma_px) +
         std::to_string(blob_pixels) + " px blob, " + std::to_string(core_pixels) + " px core" +
         Format(", second spot %.0f %% of the peak", 100.0 * second_peak, 0);
}

Highlight LocateHighlight(const Image& image, const SphereSilhouette& sphere, const PixelMask* mask,
                          const HighlightOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("highlight options", why);
  Highlight h;
  if (!sphere.fitted) {
    h.reason = "no sphere silhouette";
    return h;
  }
  const int w = image.width, ht = image.height;
  if (mask && (mask->width != w || mask->height != ht)) {
    h.reason = "the mask's size is not the photo's";
    return h;
  }
  const int channels = std::min(image.channels, 3);
  std::vector<float> value(size_t(w) * ht, 0.0f);
  std::vector<uint8_t> region(size_t(w) * ht, 0);
  const double r_search = sphere.radius_px - options.rim_margin_px;
  int peak_index = -1;
  float peak = 0.0f;
  for (int y = 0; y < ht; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if ((Eigen::Vector2d(x + 0.5, y + 0.5) - sphere.center_px).norm() > r_search) continue;
      if (mask && !mask->at(x, y)) continue;
      float v = 0.0f;
      for (int c = 0; c < channels; ++c) v += image.at(x, y, c);
      v /= float(channels);
      if (!std::isfinite(v)) continue;
      region[i] = 1;
      value[i] = v;
      if (v > peak) {
        peak = v;
        peak_index = int(i);
      }
    }
  }
  if (peak_index < 0 || !(peak > 0.0f)) {
    h.reason = "nothing bright inside the sphere's silhouette";
    return h;
  }
  h.peak = peak;
  const double level = options.blob_fraction * peak;
  const double core_level = options.core_fraction * peak;
  // The 8-connected blob around the peak.
  std::vector<uint8_t> in_blob(value.size(), 0);
  std::vector<int> stack = {peak_index}, blob;
  in_blob[peak_index] = 1;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    blob.push_back(i);
    if (int(blob.size()) > options.max_blob_pixels) break;
    const int x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= w || yy >= ht) continue;
        const int j = yy * w + xx;
        if (in_blob[j] || !region[j] || value[j] <= level) continue;
        in_blob[j] = 1;
        stack.push_back(j);
      }
    }
  }
  h.blob_pixels = int(blob.size());
  if (h.blob_pixels > options.max_blob_pixels) {
    h.reason =
        "the bright region exceeds " + std::to_string(options.max_blob_pixels) + " pixels (no compact highlight)";
    return h;
  }
  double sw = 0, sx = 0, sy = 0, cn = 0, cx = 0, cy = 0;
  for (int i : blob) {
    const double x = i % w + 0.5, y = i / w + 0.5, wt = value[i] - level;
    sw += wt;
    sx += wt * x;
    sy += wt * y;
    if (value[i] >= core_level) {
      cn += 1;
      cx += x;
      cy += y;
    }
  }
  h.pixel = Eigen::Vector2d(sx / sw, sy / sw);
  h.core = Eigen::Vector2d(cx / cn, cy / cn);
  h.core_pixels = int(cn);
  // The centroid's statistical error: var(x) = sigma^2 sum (x_i - x)^2 / (sum w)^2.
  double spread = 0.0;
  for (int i : blob) spread += (Eigen::Vector2d(i % w + 0.5, i / w + 0.5) - h.pixel).squaredNorm() / 2.0;
  const double noise = options.relative_noise * peak;
  const double statistical = noise * std::sqrt(spread) / sw;
  const double systematic = (h.core - h.pixel).norm() / 2.0;
  h.sigma_px = std::max(options.min_sigma_px, std::hypot(statistical, systematic));
  // The brightest spot elsewhere on the sphere (two pixels clear of the blob).
  float second = 0.0f;
  for (int y = 0; y < ht; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      if (!region[i] || in_blob[i] || value[i] <= second) continue;
      bool near_blob = false;
      for (int dy = -2; dy <= 2 && !near_blob; ++dy) {
        for (int dx = -2; dx <= 2 && !near_blob; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < w && yy < ht) near_blob = in_blob[size_t(yy) * w + xx] != 0;
        }
      }
      if (!near_blob) second = value[i];
    }
  }
  h.second_peak = second / peak;
  if (h.second_peak > options.max_second_peak) {
    h.reason = Format("two bright spots on the sphere (the second at %.0f %% of the peak): which is the light's?",
                      100.0 * h.second_peak, 0);
    return h;
  }
  h.found = true;
  return h;
}

bool ReflectedDirection(const Camera& camera, const SphereSilhouette& sphere, double radius,
                        const Eigen::Vector2d& pixel, Eigen::Vector3d* direction, Eigen::Vector3d* surface_point) {
  const Eigen::Vector3d ray = RayThrough(camera, pixel);
  const Eigen::Vector3d center = sphere.CenterInCamera(radius);
  const double along = ray.dot(center);
  const double off2 = (center - along * ray).squaredNorm();  // squared distance of the centre from the ray
  if (!(off2 <= radius * radius)) return false;
  const double t = along - std::sqrt(radius * radius - off2);
  const Eigen::Vector3d p = t * ray;
  const Eigen::Vector3d n = (p - center) / radius;
  *direction = (ray - 2.0 * n.dot(ray) * n).normalized();
  if (surface_point) *surface_point = p;
  return true;
}

MirrorDirection DirectionFromHighlight(const Camera& camera, const SphereSilhouette& sphere, double radius,
                                       const Highlight& highlight) {
  MirrorDirection out;
  if (!highlight.found) {
    out.reason = highlight.reason;
    return out;
  }
  if (!ReflectedDirection(camera, sphere, radius, highlight.pixel, &out.direction, &out.surface_point)) {
    out.reason = "the highlight lies outside the sphere's silhouette";
    return out;
  }
  // Jacobian of the direction in (highlight x, y, cone p0, p1, half angle), by central differences.
  Eigen::Matrix<double, 3, 5> J;
  const Eigen::Vector3d p0(sphere.axis.x() / sphere.axis.z(), sphere.axis.y() / sphere.axis.z(), sphere.half_angle);
  for (int k = 0; k < 5; ++k) {
    Eigen::Vector3d plus, minus;
    double h;
    if (k < 2) {
      h = 1e-3;
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      d[k] = h;
      if (!ReflectedDirection(camera, sphere, radius, highlight.pixel + d, &plus, nullptr) ||
          !ReflectedDirection(camera, sphere, radius, highlight.pixel - d, &minus, nullptr)) {
        out.reason = "the highlight lies on the sphere's rim";
        return out;
      }
    } else {
      h = 1e-5 * sphere.half_angle;
      SphereSilhouette s_plus = sphere, s_minus = sphere;
      Eigen::Vector3d pp = p0, pm = p0;
      pp[k - 2] += h;
      pm[k - 2] -= h;
      s_plus.axis = AxisOf(pp);
      s_plus.half_angle = pp[2];
      s_minus.axis = AxisOf(pm);
      s_minus.half_angle = pm[2];
      if (!ReflectedDirection(camera, s_plus, radius, highlight.pixel, &plus, nullptr) ||
          !ReflectedDirection(camera, s_minus, radius, highlight.pixel, &minus, nullptr)) {
        out.reason = "the highlight lies on the sphere's rim";
        return out;
      }
    }
    J.col(k) = (plus - minus) / (2.0 * h);
  }
  Eigen::Matrix<double, 5, 5> sigma = Eigen::Matrix<double, 5, 5>::Zero();
  sigma(0, 0) = sigma(1, 1) = highlight.sigma_px * highlight.sigma_px;
  const Eigen::Matrix3d from_highlight = J * sigma * J.transpose();
  sigma.block<3, 3>(2, 2) = sphere.covariance;
  out.covariance = J * sigma * J.transpose();
  out.sigma_deg = std::sqrt(std::max(0.0, out.covariance.trace())) * 180.0 / kPi;
  out.sigma_from_highlight_deg = std::sqrt(std::max(0.0, from_highlight.trace())) * 180.0 / kPi;
  out.valid = true;
  return out;
}

bool TriangulateRays(const std::vector<Eigen::Vector3d>& origins, const std::vector<Eigen::Vector3d>& directions,
                     const std::vector<double>& sigma_rad, Eigen::Vector3d* point, Eigen::Matrix3d* covariance) {
  const size_t n = origins.size();
  if (n < 2 || directions.size() != n || sigma_rad.size() != n) return false;
  std::vector<double> weight(n, 1.0);
  for (int round = 0; round < 2; ++round) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d d = directions[k].normalized();
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
      A += weight[k] * P;
      b += weight[k] * P * origins[k];
    }
    if (round == 0) {
      // Nearly parallel rays: the point along them is undetermined.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(A / double(n));
      if (!(eigen.eigenvalues()[0] > 1e-5)) return false;
    }
    *point = A.ldlt().solve(b);
    if (round == 1) {
      *covariance = A.inverse();
      break;
    }
    for (size_t k = 0; k < n; ++k) {
      const double s = std::max(1e-12, sigma_rad[k] * (*point - origins[k]).norm());
      weight[k] = 1.0 / (s * s);
    }
  }
  return point->allFinite();
}

}  // namespace ibrdf
