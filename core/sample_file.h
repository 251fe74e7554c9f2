// BRDF sample files: one row per measured (pixel, photo) pair, as a NumPy .npy structured array, so a
// Python user loads it with one call:
//
//   s = numpy.load("samples.npy");  s["brdf"][:, 0]  # red BRDF values, 1/sr
//
// Fields (all little-endian, 76 bytes a row; version 1 files, 72 bytes without `valid` and
// `exposures`, are still read):
//   wi, wo      float32 x3  unit directions to the light and to the camera, local frame (z = normal)
//   theta_i, theta_e, delta_phi   float32  radians; delta_phi = phi_e - phi_i in (-pi, pi]
//   brdf        float32 x3  RGB BRDF value, 1/sr
//   sigma       float32 x3  one-sigma uncertainty of brdf from the camera noise model (0 if unknown)
//   image       uint32      index of the photo in the session's "photos" list
//   pixel       uint32 x2   column and row of the pixel
//   valid       uint8 x3    per channel: 1 = measured, 0 = not (clipped, below the signal floor, not
//                           finite): brdf[c] is then no measurement and readers leave it out
//   exposures   uint8       exposures of a bracket merged into the pixel (1: one photo; 0: not recorded)
// A JSON sidecar (<file>.json, see docs/sample-format.md) holds units, colour space, counts and the
// session the samples came from.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/npy.h"

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
  uint8_t valid[3] = {1, 1, 1};  // per channel: 1 measured, 0 not (docs/sample-format.md)
  uint8_t exposures = 1;         // bracket exposures merged (0: not recorded, a version 1 file)

  // Whether channel c is a measurement.
  bool Valid(int c) const { return valid[c] != 0; }
  // Whether every channel is a measurement.
  bool AllValid() const { return valid[0] && valid[1] && valid[2]; }
};
#pragma pack(pop)
static_assert(sizeof(BrdfSample) == 76, "BrdfSample must match the .npy dtype");

// The NumPy dtype description of BrdfSample as written in the .npy header.
const char* BrdfSampleDtype();
// The dtype of version 1 sample files (72 bytes a row, every channel valid), which ReadSamples still reads.
const char* BrdfSampleDtypeVersion1();

// Writes samples as .npy atomically.
void WriteSamples(const std::string& path, const std::vector<BrdfSample>& samples);

// A sample file written row by row (NpyRowWriter): byte for byte what WriteSamples writes for the
// same rows, at `path` directly (an AtomicFile's temporary path: the final file appears on commit).
class SampleFileWriter {
 public:
  explicit SampleFileWriter(const std::string& path);
  void Append(const BrdfSample* samples, size_t count) { writer_.Append(samples, count); }
  uint64_t rows() const { return writer_.rows(); }
  void Finish() { writer_.Finish(); }

 private:
  NpyRowWriter writer_;
};

// Why a sample is not a valid measurement ("" when it is): non-finite values, |wi| or |wo| not 1,
// theta_i or theta_e outside [0, pi/2], delta_phi outside [-pi, pi], a negative BRDF or sigma, a
// `valid` flag other than 0 or 1, or no valid channel.
std::string InvalidSampleReason(const BrdfSample& sample);

// Reads a .npy written by WriteSamples (or by NumPy with the same dtype), or a version 1 file (its rows
// get every channel valid and exposures 0); throws Error naming the file if the header, dtype or size
// do not match, or naming the first invalid sample (InvalidSampleReason).
std::vector<BrdfSample> ReadSamples(const std::string& path);

// Reads a sample file as ReadSamples does but `chunk_rows` rows at a time, in file order, so memory stays
// bounded whatever the file's size: `chunk(rows, count, first)` gets each chunk's rows (valid until it
// returns; `first` is the index of rows[0] in the file) after every one of them passed the checks.
// Throws as ReadSamples does, naming the file and the first invalid row. Returns the file's row count.
uint64_t ForEachSampleChunk(const std::string& path, size_t chunk_rows,
                            const std::function<void(const BrdfSample* rows, size_t count, uint64_t first)>& chunk);

// The sidecar path for a sample file: "<path>.json".
std::string SidecarPath(const std::string& samples_path);

}  // namespace ibrdf
