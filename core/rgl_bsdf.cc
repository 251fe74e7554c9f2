#include "core/rgl_bsdf.h"

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/math.h"
#include "core/tensor_file.h"

namespace ibrdf {
namespace {

float ThetaToU(float theta) { return std::sqrt(theta * (2.0f / kPiFloat)); }
float PhiToU(float phi) { return (phi + kPiFloat) / (2.0f * kPiFloat); }

}  // namespace

RglBsdf::RglBsdf(const std::string& path) : path_(path) {
  const TensorFile file = ReadTensorFile(path);
  if (!file.count("rgb") && file.count("spectra")) {
    ThrowError(path, "a spectral file (\"spectra\" without \"rgb\"): ibrdf reads the RGB files (*_rgb.bsdf)");
  }
  const TensorField& description = RequireField(file, path, "description", TensorType::kUInt8, 1);
  const TensorField& theta_i = RequireField(file, path, "theta_i", TensorType::kFloat32, 1);
  const TensorField& phi_i = RequireField(file, path, "phi_i", TensorType::kFloat32, 1);
  const TensorField& ndf = RequireField(file, path, "ndf", TensorType::kFloat32, 2);
  const TensorField& sigma = RequireField(file, path, "sigma", TensorType::kFloat32, 2);
  const TensorField& vndf = RequireField(file, path, "vndf", TensorType::kFloat32, 4);
  const TensorField& luminance = RequireField(file, path, "luminance", TensorType::kFloat32, 4);
  const TensorField& rgb = RequireField(file, path, "rgb", TensorType::kFloat32, 5);
  const TensorField& jacobian = RequireField(file, path, "jacobian", TensorType::kUInt8, 1);
  const uint64_t n_phi = phi_i.shape[0], n_theta = theta_i.shape[0];
  auto expect = [&](bool ok, const std::string& field, const std::string& what) {
    if (!ok) ThrowError(path + ": field \"" + field + "\"", what);
  };
  expect(n_phi >= 1 && n_theta >= 1, "theta_i", "theta_i and phi_i need at least one value each");
  expect(vndf.shape[0] == n_phi && vndf.shape[1] == n_theta, "vndf",
         "is " + vndf.Describe() + ", expected [phi_i, theta_i, ...] = [" + std::to_string(n_phi) + ", " +
             std::to_string(n_theta) + ", ...]");
  expect(luminance.shape[0] == n_phi && luminance.shape[1] == n_theta && luminance.shape[2] == luminance.shape[3],
         "luminance", "is " + luminance.Describe() + ", expected [phi_i, theta_i, n, n]");
  expect(rgb.shape[0] == n_phi && rgb.shape[1] == n_theta && rgb.shape[2] == 3 && rgb.shape[3] == luminance.shape[2] &&
             rgb.shape[4] == luminance.shape[3],
         "rgb", "is " + rgb.Describe() + ", expected [phi_i, theta_i, 3, n, n] with luminance's n");
  expect(jacobian.shape[0] == 1, "jacobian", "expected one uint8");
  for (const TensorField* f : {&ndf, &sigma, &vndf, &luminance, &rgb}) {
    if (f->shape[f->shape.size() - 1] < 2 || f->shape[f->shape.size() - 2] < 2) {
      ThrowError(path, "a table of shape " + f->Describe() + " is smaller than 2 x 2");
    }
  }
  description_.assign(description.data.begin(), description.data.end());
  isotropic_ = n_phi <= 2;
  const std::vector<float> phi_values = phi_i.Floats(), theta_values = theta_i.Floats();
  if (!isotropic_) {
    const int reduction = int(std::rint(2.0 * M_PI / (phi_values.back() - phi_values.front())));
    if (reduction != 1)
      ThrowError(path + ": field \"phi_i\"",
                 "a symmetry reduction of " + std::to_string(reduction) + " (only 1 is supported, as in brdf-loader)");
  }
  for (size_t i = 1; i < theta_values.size(); ++i) {
    expect(theta_values[i] > theta_values[i - 1], "theta_i", "values must increase");
  }
  const std::vector<float> ndf_data = ndf.Floats(), sigma_data = sigma.Floats(), vndf_data = vndf.Floats(),
                           rgb_data = rgb.Floats();
  for (const auto* data : {&ndf_data, &sigma_data, &vndf_data, &rgb_data}) {
    for (float v : *data) {
      if (!std::isfinite(v)) ThrowError(path, "a table holds a non-finite value");
    }
  }
  ndf_ = PiecewiseLinear2D(uint32_t(ndf.shape[1]), uint32_t(ndf.shape[0]), ndf_data.data(), {}, false, false);
  sigma_ = PiecewiseLinear2D(uint32_t(sigma.shape[1]), uint32_t(sigma.shape[0]), sigma_data.data(), {}, false, false);
  vndf_ =
      PiecewiseLinear2D(uint32_t(vndf.shape[3]), uint32_t(vndf.shape[2]), vndf_data.data(), {phi_values, theta_values});
  rgb_ = PiecewiseLinear2D(uint32_t(rgb.shape[4]), uint32_t(rgb.shape[3]), rgb_data.data(),
                           {phi_values, theta_values, {0.0f, 1.0f, 2.0f}}, false, false);
}

Eigen::Vector3d RglBsdf::EvalCosine(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const {
  if (p.z() <= 0.0 || q.z() <= 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3f wi = p.cast<float>(), wo = q.cast<float>();
  const Eigen::Vector3f wm = (wi + wo).normalized();
  const float theta_i = std::acos(std::min(wi.z(), 1.0f)), phi_i = std::atan2(wi.y(), wi.x());
  const float theta_m = std::acos(std::min(wm.z(), 1.0f)), phi_m = std::atan2(wm.y(), wm.x());
  const Eigen::Vector2f u_wi(ThetaToU(theta_i), PhiToU(phi_i));
  Eigen::Vector2f u_wm(ThetaToU(theta_m), PhiToU(isotropic_ ? phi_m - phi_i : phi_m));
  u_wm.y() -= std::floor(u_wm.y());
  const float params[2] = {phi_i, theta_i};
  const Eigen::Vector2f sample = vndf_.Invert(u_wm, params).first;
  Eigen::Vector3d f;
  for (int c = 0; c < 3; ++c) {
    const float params_rgb[3] = {phi_i, theta_i, float(c)};
    f[c] = std::max(0.0f, rgb_.Eval(sample, params_rgb));
  }
  return f * double(ndf_.Eval(u_wm, params) / (4.0f * sigma_.Eval(u_wi, params)));
}

Eigen::Vector3d RglBsdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Eigen::Vector3d::Zero();
  return EvalCosine(wo, wi) / wi.z();
}

nlohmann::json RglBsdf::ToJson() const {
  return {{"model", "rgl_bsdf"}, {"file", std::filesystem::absolute(path_).string()}};
}

bool IsRglBsdfPath(const std::string& path) {
  return path.size() > 5 && path.compare(path.size() - 5, 5, ".bsdf") == 0;
}

}  // namespace ibrdf
