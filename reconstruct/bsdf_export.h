// An isotropic BRDF to an RGL ".bsdf" tensor file (Dupuy and Jakob 2018), the format that Mitsuba 3's
// and pbrt-v4's `measured` materials and rgl-epfl's brdf-loader read (core/rgl_bsdf.h reads it back).
//
// The tables follow the paper's parameterization, built from the BRDF instead of a gonioreflectometer:
//   ndf        D(theta_m) from retro-reflection, D proportional to Y(f(w, w)) cos^2 theta (a microfacet
//              BRDF at retro-reflection is F G1^2 D / (4 cos^2); Fresnel and shadowing are left in),
//              floored at 1e-3 of its peak and normalized so that the integral of D cos theta_m is 1;
//              tabulated over u = sqrt(2 theta_m / pi) (constant in phi);
//   sigma      the projected microfacet area sigma(w_i) = integral of D(m) max(0, w_i . m) dm;
//   vndf       per incidence angle, the visible normals' density D(m) max(0, w_i . m) (G1 and 1/cos
//              theta_i are constant per slice and normalized away) times the Jacobian of u-space,
//              2 pi^2 u_theta sin theta_m, over (u_theta_m, u_phi_m);
//   rgb        per incidence angle, at every node s of the square that the VNDF warp maps to half vector
//              m = vndf.Sample(s): f(w_i, w_o) cos theta_o 4 sigma(w_i) / ndf(m), w_o the mirror of w_i
//              about m (0 below the horizon), so that a reader's rgb(s) ndf / (4 sigma) returns
//              f cos theta_o exactly at the nodes and interpolates between them;
//   luminance  the rgb tables' luminance (Rec. 709 weights), for the readers' importance sampling;
//   spectra, wavelengths  the rgb tables as a box-like spectrum (blue below 470 nm, green 500 to
//              560 nm, red above 590 nm, linear between; not colour-exact) for the spectral readers
//              (pbrt-v4, Mitsuba 3), which need these two fields;
//   theta_i    the incidence angles (radians, uniform from 0 to max_theta_i_deg), phi_i one value (0:
//              isotropic), jacobian 1, description the given text.
// The grid adapts to the BRDF: where D is peaked the VNDF warp puts most rgb nodes near the peak.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/tensor_file.h"

namespace ibrdf {

struct BsdfExportOptions {
  int theta_i_count = 23;         // incidence angles tabulated (theta_i nodes), >= 2
  double max_theta_i_deg = 88.0;  // the last one (readers clamp beyond it), in (0, 90)
  int ndf_size = 128;             // NDF and sigma columns over u = sqrt(2 theta / pi), >= 4
  int vndf_size = 64;             // VNDF rows (phi_m) and columns (theta_m) per incidence angle, >= 4
  int rgb_size = 64;              // rgb, spectra and luminance nodes per side of the warped square, >= 4
  bool Check(std::string* why) const;
};

// Evaluates f(wi, wo) (RGB, 1/sr) at many direction pairs of the local frame at once.
using BrdfBatch = std::function<void(const std::vector<Eigen::Vector3d>& wi, const std::vector<Eigen::Vector3d>& wo,
                                     std::vector<Eigen::Vector3d>* f)>;

struct BsdfExportSummary {
  bool success = false;
  size_t evaluations = 0;  // BRDF evaluations (rgb nodes above the horizon and the retro-reflection curve)
  double seconds = 0.0;
  std::string BriefReport() const;
};

// The tensor file's fields for the BRDF `brdf` (isotropic) with the description `description`
// (written into the file). Throws Error on bad options.
TensorFile BuildRglBsdf(const BrdfBatch& brdf, const std::string& description, const BsdfExportOptions& options,
                        BsdfExportSummary* summary = nullptr);

}  // namespace ibrdf
