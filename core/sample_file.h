// BRDF sample files: one row per measured (pixel, photo) pair, as a NumPy .npy structured array, so a
// Python user loads it with one call:
//
//   s = numpy.load("samples.npy");  s["brdf"][:, 0]  # red BRDF values, 1/sr
//
// Fields (all little-endian, 72 bytes a row):
//   wi, wo      float32 x3  unit directions to the light and to the camera, local frame (z = normal)
//   theta_i, theta_e, delta_phi   float32  radians; delta_phi = phi_e - phi_i in (-pi, pi]
//   brdf        float32 x3  RGB BRDF value, 1/sr
//   sigma       float32 x3  one-sigma uncertainty of brdf from the camera noise model (0 if unknown)
//   image       uint32      index of the photo in the session's "photos" list
//   pixel       uint32 x2   column and row of the pixel
// A JSON sidecar (<file>.json, see docs/sample-format.md) holds units, colour space, counts and the
// session the samples came from.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace ibrdf {

#pragma pack(push, 1)
struct BrdfSample {
  float wi[3];
  float wo[3];
  float theta_i;
  float theta_e;
  float delta_phi;
  float brdf[3];
  float sigma[3];
  uint32_t image;
  uint32_t pixel[2];
};
#pragma pack(pop)
static_assert(sizeof(BrdfSample) == 72, "BrdfSample must match the .npy dtype");

// The NumPy dtype description of BrdfSample as written in the .npy header.
const char* BrdfSampleDtype();

// Writes samples as .npy atomically.
void WriteSamples(const std::string& path, const std::vector<BrdfSample>& samples);

// Why a sample is not a valid measurement ("" when it is): non-finite values, |wi| or |wo| not 1,
// theta_i or theta_e outside [0, pi/2], delta_phi outside [-pi, pi], a negative BRDF or sigma.
std::string InvalidSampleReason(const BrdfSample& sample);

// Reads a .npy written by WriteSamples (or by NumPy with the same dtype); throws Error naming the file
// if the header, dtype or size do not match, or naming the first invalid sample (InvalidSampleReason).
std::vector<BrdfSample> ReadSamples(const std::string& path);

// The sidecar path for a sample file: "<path>.json".
std::string SidecarPath(const std::string& samples_path);

}  // namespace ibrdf
