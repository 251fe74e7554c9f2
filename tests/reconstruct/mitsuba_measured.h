// An RGL ".bsdf" file read the way Mitsuba 3's `measured` plugin reads it, for the tests: Mitsuba
// honours the file's `jacobian` flag, while brdf-loader, pbrt-v4 and core/rgl_bsdf.h multiply by
// ndf / (4 sigma) whatever it says, so only a reader that follows Mitsuba notices a file whose flag is
// wrong. Followed line by line from mitsuba-renderer/mitsuba3 src/bsdfs/measured.cpp at commit 0fe85db
// (line numbers of that version):
//   ~101-117  a file with a "wavelengths" field is spectral: its "spectra" are read, and an RGB variant
//             refuses it (~108-109); otherwise "rgb" is read with the "wavelengths" 0, 1, 2 (~110-116),
//             and a spectral variant refuses it (~112-113);
//   ~165-166  m_isotropic = phi_i has at most 2 values; m_jacobian = the file's one uint8;
//   ~174-219  the tables as Marginal2D: ndf and sigma raw (no normalization, no CDF), vndf normalized
//             with its CDF over (phi_i, theta_i), spectra raw over (phi_i, theta_i, wavelength);
//   ~237-240  elevation(d) = 2 asin(|d - (0, 0, 1)| / 2);
//   ~345-397  eval(si.wi, wo): 0 unless both cosines are positive (~351-352); m = normalize(wo + wi)
//             (~367); u_wi = (sqrt(2 theta_i / pi), (phi_i + pi) / 2 pi), u_m likewise with
//             phi_m - phi_i for an isotropic file, wrapped to [0, 1) (~376-380);
//             sample = vndf.invert(u_m | phi_i, theta_i) (~382-383); spec = spectra.eval(sample |
//             phi_i, theta_i, lambda) per wavelength, not clamped (~385-390); times
//             ndf.eval(u_m) / (4 sigma.eval(u_wi)) only `if (m_jacobian)` (~392-394).
// Mitsuba's si.wi is the direction towards the camera, and eval returns f cos(theta_o), wo the light's.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/math.h"
#include "core/piecewise_linear_2d.h"
#include "core/tensor_file.h"

namespace ibrdf::testing {

class MitsubaMeasured {
 public:
  // `spectral_variant`: a spectral variant of Mitsuba (scalar_spectral), else an RGB one (scalar_rgb).
  // Throws std::runtime_error where Mitsuba throws (the file's kind does not suit the variant).
  MitsubaMeasured(const std::string& path, bool spectral_variant) {
    const TensorFile file = ReadTensorFile(path);
    spectral_ = file.count("wavelengths") > 0;
    if (spectral_ && !spectral_variant) {
      throw std::runtime_error("Measurements in spectral format require the use of a spectral variant of Mitsuba!");
    }
    if (!spectral_ && spectral_variant) {
      throw std::runtime_error("Measurements in RGB format require the use of a RGB variant of Mitsuba!");
    }
    const TensorField& spectra = file.at(spectral_ ? "spectra" : "rgb");
    wavelengths_ = spectral_ ? file.at("wavelengths").Floats() : std::vector<float>{0.0f, 1.0f, 2.0f};
    const std::vector<float> phi_i = file.at("phi_i").Floats(), theta_i = file.at("theta_i").Floats();
    isotropic_ = phi_i.size() <= 2;
    jacobian_ = file.at("jacobian").data.at(0) != 0;
    const TensorField &ndf = file.at("ndf"), &sigma = file.at("sigma"), &vndf = file.at("vndf");
    const std::vector<float> ndf_data = ndf.Floats(), sigma_data = sigma.Floats(), vndf_data = vndf.Floats(),
                             spectra_data = spectra.Floats();
    ndf_ = PiecewiseLinear2D(uint32_t(ndf.shape[1]), uint32_t(ndf.shape[0]), ndf_data.data(), {}, false, false);
    sigma_ = PiecewiseLinear2D(uint32_t(sigma.shape[1]), uint32_t(sigma.shape[0]), sigma_data.data(), {}, false, false);
    vndf_ = PiecewiseLinear2D(uint32_t(vndf.shape[3]), uint32_t(vndf.shape[2]), vndf_data.data(), {phi_i, theta_i});
    spectra_ = PiecewiseLinear2D(uint32_t(spectra.shape[4]), uint32_t(spectra.shape[3]), spectra_data.data(),
                                 {phi_i, theta_i, wavelengths_}, false, false);
  }

  bool spectral() const { return spectral_; }
  bool jacobian() const { return jacobian_; }

  // BSDF::eval with si.wi = `camera`, wo = `light` (local frame) at each of `lambdas` (nm in a spectral
  // variant, the channels 0, 1, 2 in an RGB one): f cos(theta_light).
  std::vector<double> Eval(const Eigen::Vector3d& camera, const Eigen::Vector3d& light,
                           const std::vector<float>& lambdas) const {
    std::vector<double> spec(lambdas.size(), 0.0);
    if (!(camera.z() > 0.0 && light.z() > 0.0)) return spec;
    const Eigen::Vector3f wi = camera.cast<float>(), wo = light.cast<float>();
    const Eigen::Vector3f m = (wo + wi).normalized();
    const float theta_i = Elevation(wi), phi_i = std::atan2(wi.y(), wi.x());
    const float theta_m = Elevation(m), phi_m = std::atan2(m.y(), m.x());
    const Eigen::Vector2f u_wi(ThetaToU(theta_i), PhiToU(phi_i));
    Eigen::Vector2f u_m(ThetaToU(theta_m), PhiToU(isotropic_ ? phi_m - phi_i : phi_m));
    u_m.y() -= std::floor(u_m.y());
    const float params[2] = {phi_i, theta_i};
    const Eigen::Vector2f sample = vndf_.Invert(u_m, params).first;
    const float scale = jacobian_ ? ndf_.Eval(u_m, params) / (4.0f * sigma_.Eval(u_wi, params)) : 1.0f;
    for (size_t i = 0; i < lambdas.size(); ++i) {
      const float params_spec[3] = {phi_i, theta_i, lambdas[i]};
      spec[i] = double(spectra_.Eval(sample, params_spec) * scale);
    }
    return spec;
  }

 private:
  static float Elevation(const Eigen::Vector3f& d) {
    const float dist = std::sqrt(d.x() * d.x() + d.y() * d.y() + (d.z() - 1.0f) * (d.z() - 1.0f));
    return 2.0f * std::asin(std::min(1.0f, 0.5f * dist));
  }
  static float ThetaToU(float theta) { return std::sqrt(theta * (2.0f / kPiFloat)); }
  static float PhiToU(float phi) { return (phi + kPiFloat) / (2.0f * kPiFloat); }

  bool spectral_ = false, isotropic_ = true, jacobian_ = true;
  std::vector<float> wavelengths_;
  PiecewiseLinear2D ndf_, sigma_, vndf_, spectra_;
};

}  // namespace ibrdf::testing
