// The report's rendered spheres: a BRDF seen on a sphere under a distant light, the way a photo of the
// sample at a given phase angle would show it.
#pragma once

#include <functional>

#include <Eigen/Core>

#include "core/image_io.h"

namespace ibrdf {

// A BRDF f(wi, wo) in the local shading frame (z the normal), RGB in 1/sr; a negative channel means
// "no value".
using BrdfEvalFunction = std::function<Eigen::Vector3d(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo)>;

// A unit sphere filling a `size` x `size` image, seen orthographically from +z (y up), lit by a
// distant light at `phase` radians from the view direction in the horizontal plane (from the left),
// unit irradiance at normal incidence: each pixel holds the radiance f cos(theta_i). The background and
// the unlit side are 0; pixels where `eval` has no value are NaN.
Image RenderSphere(int size, double phase, const BrdfEvalFunction& eval);

}  // namespace ibrdf
