#include "reconstruct/bsdf_export.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/piecewise_linear_2d.h"

namespace ibrdf {
namespace {

double Luminance(const Eigen::Vector3d& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

Eigen::Vector3d Direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

// The box-like spectrum's nodes (nm) and the RGB channel each one takes.
const float kWavelengths[] = {360.0f, 470.0f, 500.0f, 560.0f, 590.0f, 830.0f};
const int kWavelengthChannel[] = {2, 2, 1, 1, 0, 0};

}  // namespace

bool BsdfExportOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(theta_i_count >= 2 && theta_i_count <= 1000);
  IBRDF_CHECK_OPTION(max_theta_i_deg > 0.0 && max_theta_i_deg < 90.0);
  IBRDF_CHECK_OPTION(ndf_size >= 4 && ndf_size <= 4096);
  IBRDF_CHECK_OPTION(vndf_size >= 4 && vndf_size <= 4096);
  IBRDF_CHECK_OPTION(rgb_size >= 4 && rgb_size <= 4096);
  return true;
}

std::string BsdfExportSummary::BriefReport() const {
  std::ostringstream out;
  out << "RGL .bsdf: " << (success ? "" : "FAILED, ") << evaluations << " BRDF evaluations, " << seconds << " s";
  return out.str();
}

namespace {

// D(theta_m) at the NDF's nodes from retro-reflection over u = sqrt(2 theta / pi): f(w, w) cos^2
// theta, floored at 1e-3 of its peak (not yet normalized).
std::vector<double> RetroReflectionNdf(const BrdfBatch& brdf, int n_ndf, size_t* evaluations) {
  std::vector<Eigen::Vector3d> retro_dirs(n_ndf), retro_f;
  for (int j = 0; j < n_ndf; ++j) {
    const double u = double(j) / (n_ndf - 1), theta = std::min(u * u * kPi / 2, kPi / 2 - 1e-4);
    retro_dirs[j] = Direction(theta, 0.0);
  }
  brdf(retro_dirs, retro_dirs, &retro_f);
  *evaluations += n_ndf;
  std::vector<double> d(n_ndf);
  double peak = 0.0;
  for (int j = 0; j < n_ndf; ++j) {
    const double c = retro_dirs[j].z();
    d[j] = std::isfinite(Luminance(retro_f[j])) ? std::max(0.0, Luminance(retro_f[j])) * c * c : 0.0;
    peak = std::max(peak, d[j]);
  }
  if (!(peak > 0.0)) peak = 1.0;  // a black BRDF: any positive D serves
  for (double& v : d) v = std::max(v, 1e-3 * peak);
  return d;
}

// D as a function of theta (linear in u between the nodes, as the readers interpolate).
double NdfAt(const std::vector<double>& d, double theta) {
  const int n_ndf = int(d.size());
  const double x = std::sqrt(std::clamp(theta, 0.0, kPi / 2) * 2 / kPi) * (n_ndf - 1);
  const int j = std::min(int(x), n_ndf - 2);
  return d[j] + (x - j) * (d[j + 1] - d[j]);
}

// The integral of D cos theta over the hemisphere (midpoint rule in theta).
double ProjectedNdfIntegral(const std::vector<double>& d) {
  const int n_int = 2048;
  double integral = 0.0;
  for (int k = 0; k < n_int; ++k) {
    const double theta = (k + 0.5) / n_int * kPi / 2;
    integral += NdfAt(d, theta) * std::cos(theta) * std::sin(theta) * (kPi / 2 / n_int) * 2 * kPi;
  }
  return integral;
}

// sigma(theta_i) = integral of D(m) max(0, w_i . m) dm at the NDF's nodes, on a (theta_m, phi_m)
// midpoint grid; D is NdfAt(d) / integral. Stored twice (phi 0 and 2 pi), like the NDF.
std::vector<float> ProjectedAreas(const std::vector<double>& d, double integral) {
  const int n_ndf = int(d.size());
  const int n_t = 384, n_p = 192;
  std::vector<Eigen::Vector3d> m_dirs;  // the grid's half vectors, each times D sin(theta) dtheta dphi
  m_dirs.reserve(size_t(n_t) * n_p);
  for (int a = 0; a < n_t; ++a) {
    const double theta = (a + 0.5) / n_t * kPi / 2;
    const double weight = NdfAt(d, theta) / integral * std::sin(theta) * (kPi / 2 / n_t) * (2 * kPi / n_p);
    for (int b = 0; b < n_p; ++b) m_dirs.push_back(weight * Direction(theta, (b + 0.5) / n_p * 2 * kPi - kPi));
  }
  std::vector<float> sigma(2 * size_t(n_ndf));
  tbb::parallel_for(0, n_ndf, [&](int j) {
    const double u = double(j) / (n_ndf - 1);
    const Eigen::Vector3d wi = Direction(u * u * kPi / 2, 0.0);
    double s = 0.0;
    for (const Eigen::Vector3d& m : m_dirs) s += std::max(0.0, wi.dot(m));
    sigma[j] = sigma[n_ndf + j] = float(s);
  });
  return sigma;
}

// The visible NDF per incidence angle, D(m) max(0, w_i . m) with the Jacobian of the (u, phi) square.
std::vector<float> VisibleNdf(const PiecewiseLinear2D& ndf_table, const std::vector<float>& theta_i, int n_vndf) {
  const int n_theta = int(theta_i.size());
  std::vector<float> vndf(size_t(n_theta) * n_vndf * n_vndf);
  tbb::parallel_for(0, n_theta, [&](int k) {
    const Eigen::Vector3d wi = Direction(theta_i[k], 0.0);
    for (int y = 0; y < n_vndf; ++y) {
      const double phi = (2.0 * y / (n_vndf - 1) - 1.0) * kPi;
      for (int x = 0; x < n_vndf; ++x) {
        const double u = double(x) / (n_vndf - 1), theta = u * u * kPi / 2;
        const Eigen::Vector2f u_m(float(u), float(y) / float(n_vndf - 1));
        const double dm = ndf_table.Eval(u_m);
        vndf[(size_t(k) * n_vndf + y) * n_vndf + x] =
            float(dm * std::max(0.0, wi.dot(Direction(theta, phi))) * 2 * kPi * kPi * u * std::sin(theta));
      }
    }
  });
  return vndf;
}

// The rgb slices and their luminance: the half vector each node of the square maps to, its mirror
// direction, the BRDF there (per incidence angle in parallel, then evaluated in one batch, in order).
void RgbSlices(const BrdfBatch& brdf, const std::vector<float>& theta_i, const PiecewiseLinear2D& ndf_table,
               const PiecewiseLinear2D& sigma_table, const PiecewiseLinear2D& vndf_warp, int n_rgb, size_t* evaluations,
               std::vector<float>* rgb, std::vector<float>* luminance) {
  const int n_theta = int(theta_i.size());
  const size_t slice = size_t(n_rgb) * n_rgb;
  struct Nodes {
    std::vector<Eigen::Vector3d> wi, wo;
    std::vector<size_t> node_of;  // flat (k, node) index of each evaluation
  };
  std::vector<Nodes> per_theta(n_theta);
  std::vector<double> scale(size_t(n_theta) * slice, 0.0);
  tbb::parallel_for(0, n_theta, [&](int k) {
    Nodes& nodes = per_theta[k];
    const float params[2] = {0.0f, theta_i[k]};
    const Eigen::Vector3d wi = Direction(theta_i[k], 0.0);
    const double four_sigma = 4.0 * sigma_table.Eval(Eigen::Vector2f(std::sqrt(theta_i[k] * float(2 / kPi)), 0.5f));
    for (int y = 0; y < n_rgb; ++y) {
      for (int x = 0; x < n_rgb; ++x) {
        const Eigen::Vector2f s(float(x) / float(n_rgb - 1), float(y) / float(n_rgb - 1));
        const Eigen::Vector2f u_m = vndf_warp.Sample(s, params).first;
        const double theta_m = double(u_m.x()) * u_m.x() * kPi / 2, phi_m = (2.0 * u_m.y() - 1.0) * kPi;
        const Eigen::Vector3d wm = Direction(theta_m, phi_m);
        const Eigen::Vector3d wo = 2.0 * wi.dot(wm) * wm - wi;
        if (wo.z() <= 0.0) continue;
        const double ndf_m = ndf_table.Eval(u_m);
        scale[size_t(k) * slice + size_t(y) * n_rgb + x] = wo.z() * four_sigma / ndf_m;
        nodes.wi.push_back(wi);
        nodes.wo.push_back(wo.normalized());
        nodes.node_of.push_back(size_t(k) * slice + size_t(y) * n_rgb + x);
      }
    }
  });
  std::vector<Eigen::Vector3d> wi_list, wo_list, f_list;
  std::vector<size_t> node_of;
  for (const Nodes& nodes : per_theta) {
    wi_list.insert(wi_list.end(), nodes.wi.begin(), nodes.wi.end());
    wo_list.insert(wo_list.end(), nodes.wo.begin(), nodes.wo.end());
    node_of.insert(node_of.end(), nodes.node_of.begin(), nodes.node_of.end());
  }
  brdf(wi_list, wo_list, &f_list);
  *evaluations += wi_list.size();
  rgb->assign(size_t(n_theta) * 3 * slice, 0.0f);
  luminance->assign(size_t(n_theta) * slice, 0.0f);
  for (size_t e = 0; e < node_of.size(); ++e) {
    const size_t flat = node_of[e], k = flat / slice, node = flat % slice;
    Eigen::Vector3d value = f_list[e].cwiseMax(0.0) * scale[flat];
    if (!value.allFinite()) value.setZero();
    for (int c = 0; c < 3; ++c) (*rgb)[(k * 3 + size_t(c)) * slice + node] = float(value[c]);
    (*luminance)[flat] = float(Luminance(value));
  }
  // Luminance floored per slice (a slice must integrate to a positive value for the sampling warp).
  for (int k = 0; k < n_theta; ++k) {
    float* l = luminance->data() + size_t(k) * slice;
    const float top = *std::max_element(l, l + slice);
    const float floor = top > 0.0f ? 1e-4f * top : 1.0f;
    for (size_t i = 0; i < slice; ++i) l[i] = std::max(l[i], floor);
  }
}

// The box-like spectra: each wavelength node takes its RGB channel's slice.
std::vector<float> BoxSpectra(const std::vector<float>& rgb, int n_theta, size_t slice) {
  const size_t n_lambda = std::size(kWavelengths);
  std::vector<float> spectra(size_t(n_theta) * n_lambda * slice);
  for (int k = 0; k < n_theta; ++k) {
    for (size_t w = 0; w < n_lambda; ++w) {
      std::copy_n(rgb.data() + (size_t(k) * 3 + size_t(kWavelengthChannel[w])) * slice, slice,
                  spectra.data() + (size_t(k) * n_lambda + w) * slice);
    }
  }
  return spectra;
}

}  // namespace

TensorFile BuildRglBsdf(const BrdfBatch& brdf, const std::string& description, const BsdfExportOptions& options,
                        BsdfExportSummary* summary) {
  std::string why;
  if (!options.Check(&why)) ThrowError("RGL .bsdf export options", why);
  const Timer timer;
  const int n_theta = options.theta_i_count, n_ndf = options.ndf_size, n_vndf = options.vndf_size,
            n_rgb = options.rgb_size;
  size_t evaluations = 0;

  // The NDF, normalized so that the integral of D cos theta over the hemisphere is 1, and sigma.
  std::vector<double> d = RetroReflectionNdf(brdf, n_ndf, &evaluations);
  const double integral = ProjectedNdfIntegral(d);
  for (double& v : d) v /= integral;
  std::vector<float> ndf(2 * size_t(n_ndf));
  for (int j = 0; j < n_ndf; ++j) ndf[j] = ndf[n_ndf + j] = float(d[j]);
  // ProjectedAreas divides the normalized D by `integral` once more; changing that changes every exported file.
  const std::vector<float> sigma = ProjectedAreas(d, integral);
  const PiecewiseLinear2D ndf_table(static_cast<uint32_t>(n_ndf), 2, ndf.data(), {}, false, false);
  const PiecewiseLinear2D sigma_table(static_cast<uint32_t>(n_ndf), 2, sigma.data(), {}, false, false);

  // The incidence angles and the VNDF per angle.
  std::vector<float> theta_i(n_theta);
  for (int k = 0; k < n_theta; ++k) theta_i[k] = float(double(k) / (n_theta - 1) * options.max_theta_i_deg * kPi / 180);
  const std::vector<float> phi_i = {0.0f};
  std::vector<float> vndf = VisibleNdf(ndf_table, theta_i, n_vndf);
  const PiecewiseLinear2D vndf_warp(static_cast<uint32_t>(n_vndf), static_cast<uint32_t>(n_vndf), vndf.data(),
                                    {phi_i, theta_i});

  std::vector<float> rgb, luminance;
  RgbSlices(brdf, theta_i, ndf_table, sigma_table, vndf_warp, n_rgb, &evaluations, &rgb, &luminance);
  const size_t n_lambda = std::size(kWavelengths);
  const std::vector<float> spectra = BoxSpectra(rgb, n_theta, size_t(n_rgb) * n_rgb);

  TensorFile file;
  const uint64_t T = uint64_t(n_theta), R = uint64_t(n_rgb), V = uint64_t(n_vndf), N = uint64_t(n_ndf);
  file["description"] = TextField(description);
  file["theta_i"] = FloatField({T}, theta_i);
  file["phi_i"] = FloatField({1}, phi_i);
  file["ndf"] = FloatField({2, N}, ndf);
  file["sigma"] = FloatField({2, N}, sigma);
  file["vndf"] = FloatField({1, T, V, V}, vndf);
  file["luminance"] = FloatField({1, T, R, R}, luminance);
  file["rgb"] = FloatField({1, T, 3, R, R}, rgb);
  file["wavelengths"] = FloatField({n_lambda}, std::vector<float>(std::begin(kWavelengths), std::end(kWavelengths)));
  file["spectra"] = FloatField({1, T, n_lambda, R, R}, spectra);
  file["jacobian"] = BytesField({1});
  if (summary) {
    summary->success = true;
    summary->evaluations = evaluations;
    summary->seconds = timer.ElapsedSeconds();
  }
  return file;
}

}  // namespace ibrdf
