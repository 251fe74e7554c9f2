#include "core/sample_file.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <exception>
#include <string>

#include "core/error.h"
#include "core/npy.h"

namespace ibrdf {
namespace {

// A row of a version 1 sample file: BrdfSample without `valid` and `exposures`.
#pragma pack(push, 1)
struct BrdfSampleVersion1 {
  unsigned char bytes[72];
};
#pragma pack(pop)
static_assert(offsetof(BrdfSample, valid) == sizeof(BrdfSampleVersion1), "version 1 rows are BrdfSample's prefix");

}  // namespace

const char* BrdfSampleDtype() {
  return "[('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), ('theta_e', '<f4'), "
         "('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), ('image', '<u4'), "
         "('pixel', '<u4', (2,)), ('valid', '|u1', (3,)), ('exposures', '|u1')]";
}

const char* BrdfSampleDtypeVersion1() {
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
  if (s.valid[0] > 1 || s.valid[1] > 1 || s.valid[2] > 1) return "a valid flag is not 0 or 1";
  if (!(s.valid[0] || s.valid[1] || s.valid[2])) return "no channel is valid";
  return "";
}

std::vector<BrdfSample> ReadSamples(const std::string& path) {
  std::vector<size_t> shape;
  std::vector<BrdfSample> samples;
  try {
    samples = ReadNpy<BrdfSample>(path, BrdfSampleDtype(), &shape);
  } catch (const Error&) {
    // A version 1 file (no per-channel validity): every channel valid, exposures not recorded. Any
    // other dtype gets the message of the current format.
    const std::exception_ptr current = std::current_exception();
    std::vector<BrdfSampleVersion1> old;
    try {
      old = ReadNpy<BrdfSampleVersion1>(path, BrdfSampleDtypeVersion1(), &shape);
    } catch (const Error&) {
      std::rethrow_exception(current);
    }
    samples.resize(old.size());
    for (size_t i = 0; i < old.size(); ++i) {
      std::memcpy(static_cast<void*>(&samples[i]), &old[i], sizeof(BrdfSampleVersion1));
      samples[i].exposures = 0;
    }
  }
  if (shape.size() != 1) ThrowError(path, "sample files are one-dimensional arrays");
  for (size_t i = 0; i < samples.size(); ++i) {
    const std::string reason = InvalidSampleReason(samples[i]);
    if (!reason.empty()) ThrowError(path, "sample " + std::to_string(i) + ": " + reason);
  }
  return samples;
}

}  // namespace ibrdf
