// Smooth evaluation of a tabulated BRDF for the report's curves and renders: trilinear interpolation of
// a MERL table in its index space (theta_h on the table's square-root axis, theta_d, phi_d periodic over
// pi), instead of the reader's nearest-cell lookup, whose staircase reads as structure in a plot.
#pragma once

#include <Eigen/Core>

#include "reconstruct/merl_table.h"

namespace ibrdf {

// f(wi, wo) in 1/sr from the eight cells around the point, weighted trilinearly over the measured ones
// (weights renormalized); negative (no value) when none of the eight is measured or a direction is
// below the horizon.
Eigen::Vector3d InterpolateMerl(const MerlTable& table, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo);

}  // namespace ibrdf
