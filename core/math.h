// Numeric constants every stage shares: pi and the degree, written once.
#pragma once

namespace ibrdf {

// pi to double precision (the same double as M_PI).
inline constexpr double kPi = 3.14159265358979323846;
// One degree in radians: `angle_deg * kDegree` is radians.
inline constexpr double kDegree = kPi / 180.0;
// One radian in degrees: `angle_rad * kDegreesPerRadian` is degrees.
inline constexpr double kDegreesPerRadian = 180.0 / kPi;
// pi in single precision, for float kernels.
inline constexpr float kPiFloat = 3.14159265358979323846f;

}  // namespace ibrdf
