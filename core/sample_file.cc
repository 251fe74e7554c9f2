#include "core/sample_file.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/npy.h"

namespace ibrdf {

const char* BrdfSampleDtype() {
  return "[('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), ('theta_e', '<f4'), "
         "('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), ('image', '<u4'), "
         "('pixel', '<u4', (2,))]";
}

std::string SidecarPath(const std::string& samples_path) { return samples_path + ".json"; }

void WriteSamples(const std::string& path, const std::vector<BrdfSample>& samples) {
  WriteNpy(path, BrdfSampleDtype(), {samples.size()}, sizeof(BrdfSample), samples.data(),
           samples.size() * sizeof(BrdfSample));
}

std::string InvalidSampleReason(const BrdfSample& s) {
  constexpr float kPi = 3.14159265358979f;
  constexpr float kAngleSlack = 1e-4f;  // float32 rounding of angles at the ends of their range
  constexpr float kUnitSlack = 1e-3f;   // float32 rounding of unit vectors
  const auto finite3 = [](const float v[3]) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
  };
  const auto length = [](const float v[3]) {
    return std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
  };
  if (!finite3(s.wi) || !finite3(s.wo)) return "wi or wo is not finite";
  if (std::abs(length(s.wi) - 1.0) > kUnitSlack) return "|wi| = " + std::to_string(length(s.wi)) + ", not 1";
  if (std::abs(length(s.wo) - 1.0) > kUnitSlack) return "|wo| = " + std::to_string(length(s.wo)) + ", not 1";
  if (!(s.theta_i >= -kAngleSlack && s.theta_i <= kPi / 2 + kAngleSlack)) {
    return "theta_i = " + std::to_string(s.theta_i) + " is outside [0, pi/2]";
  }
  if (!(s.theta_e >= -kAngleSlack && s.theta_e <= kPi / 2 + kAngleSlack)) {
    return "theta_e = " + std::to_string(s.theta_e) + " is outside [0, pi/2]";
  }
  if (!(s.delta_phi >= -kPi - kAngleSlack && s.delta_phi <= kPi + kAngleSlack)) {
    return "delta_phi = " + std::to_string(s.delta_phi) + " is outside [-pi, pi]";
  }
  for (int c = 0; c < 3; ++c) {
    if (!(std::isfinite(s.brdf[c]) && s.brdf[c] >= 0)) {
      return "brdf[" + std::to_string(c) + "] = " + std::to_string(s.brdf[c]) + " is not a finite, non-negative value";
    }
    if (!(std::isfinite(s.sigma[c]) && s.sigma[c] >= 0)) {
      return "sigma[" + std::to_string(c) + "] = " + std::to_string(s.sigma[c]) +
             " is not a finite, non-negative value";
    }
  }
  return "";
}

std::vector<BrdfSample> ReadSamples(const std::string& path) {
  std::vector<size_t> shape;
  std::vector<BrdfSample> samples = ReadNpy<BrdfSample>(path, BrdfSampleDtype(), &shape);
  if (shape.size() != 1) ThrowError(path, "sample files are one-dimensional arrays");
  for (size_t i = 0; i < samples.size(); ++i) {
    const std::string reason = InvalidSampleReason(samples[i]);
    if (!reason.empty()) ThrowError(path, "sample " + std::to_string(i) + ": " + reason);
  }
  return samples;
}

}  // namespace ibrdf
