// An RGL ".bsdf" file (Dupuy and Jakob 2018, "An Adaptive Parameterization for Efficient Material
// Acquisition and Rendering"; the format of the RGL material database, of Mitsuba 3's and pbrt-v4's
// `measured` materials) as a material: `ibrdf synth --material X.bsdf`, `compare --truth X.bsdf`,
// `reconstruct --truth X.bsdf`, or {"model": "rgl_bsdf", "file": "X.bsdf"} in a material file.
//
// Evaluation is rgl-epfl/brdf-loader's (powitacq_rgb.inl, BRDF::eval), re-implemented: with p the
// parameter direction and q the other one, wm = normalize(p + q),
//   u_p = (sqrt(2 theta_p / pi), (phi_p + pi) / 2pi), u_m = (sqrt(2 theta_m / pi), (phi_m - phi_p + pi) / 2pi mod 1)
//   (isotropic files: phi_m - phi_p; anisotropic: phi_m), s = vndf.Invert(u_m | phi_p, theta_p),
//   f(p, q) cos(theta_q) = max(0, rgb(s | phi_p, theta_p, channel)) ndf(u_m) / (4 sigma(u_p)),
// every table a PiecewiseLinear2D (core/piecewise_linear_2d.h). As Mitsuba 3 does (its si.wi), the
// parameter direction is the one towards the camera: Eval(wi, wo) = that / cos(theta_i).
// Needs the RGB tables ("rgb", as in the database's *_rgb.bsdf files); spectral-only files are refused
// (ibrdf has no colour-matching to turn spectra into RGB).
#pragma once

#include <memory>
#include <string>

#include "core/brdf_model.h"
#include "core/piecewise_linear_2d.h"

namespace ibrdf {

class RglBsdf : public BrdfModel {
 public:
  // Reads and checks `path` as brdf-loader does (fields, dtypes, shapes; Error naming the file and the
  // field otherwise).
  explicit RglBsdf(const std::string& path);
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override;
  nlohmann::json ToJson() const override;
  std::string ModelName() const override { return "rgl_bsdf"; }

  // brdf-loader's BRDF::eval(p, q): f(p, q) cos(theta_q), RGB, with p the parameter direction.
  Eigen::Vector3d EvalCosine(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const;

  const std::string& path() const { return path_; }
  const std::string& description() const { return description_; }
  bool isotropic() const { return isotropic_; }

 private:
  std::string path_, description_;
  bool isotropic_ = true;
  PiecewiseLinear2D ndf_, sigma_, vndf_, rgb_;
};

// True when `path` names an RGL tensor file (by its ".bsdf" extension).
bool IsRglBsdfPath(const std::string& path);

}  // namespace ibrdf
