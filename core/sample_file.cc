#include "core/sample_file.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "core/error.h"
#include "core/math.h"
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

// Asks the kernel for transparent huge pages behind [data, data + bytes) before it is first written
// (Linux's "madvise" mode; a no-op elsewhere): 41 page faults instead of 20 000 for a demo run's
// samples. Only the whole 2 MiB pages inside the range are advised.
void AdviseHugePages(const void* data, size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (data != nullptr && end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

// InvalidSampleReason(s).empty() without building strings: true for every valid sample and false for
// most invalid ones; ReadSamples asks InvalidSampleReason only when this is false. The same tests and
// slack as InvalidSampleReason.
inline bool PlausibleSample(const BrdfSample& s) {
  constexpr float kAngleSlack = 1e-4f;
  constexpr float kUnitSlack = 1e-3f;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(s.wi[c]) || !std::isfinite(s.wo[c])) return false;
    if (!(std::isfinite(s.brdf[c]) && s.brdf[c] >= 0) || !(std::isfinite(s.sigma[c]) && s.sigma[c] >= 0)) return false;
  }
  const double wi = std::sqrt(double(s.wi[0]) * s.wi[0] + double(s.wi[1]) * s.wi[1] + double(s.wi[2]) * s.wi[2]);
  const double wo = std::sqrt(double(s.wo[0]) * s.wo[0] + double(s.wo[1]) * s.wo[1] + double(s.wo[2]) * s.wo[2]);
  return std::abs(wi - 1.0) <= kUnitSlack && std::abs(wo - 1.0) <= kUnitSlack && s.theta_i >= -kAngleSlack &&
         s.theta_i <= kPiFloat / 2 + kAngleSlack && s.theta_e >= -kAngleSlack &&
         s.theta_e <= kPiFloat / 2 + kAngleSlack && s.delta_phi >= -kPiFloat - kAngleSlack &&
         s.delta_phi <= kPiFloat + kAngleSlack && s.valid[0] <= 1 && s.valid[1] <= 1 && s.valid[2] <= 1 &&
         (s.valid[0] || s.valid[1] || s.valid[2]);
}

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
  if (!(s.theta_i >= -kAngleSlack && s.theta_i <= kPiFloat / 2 + kAngleSlack)) {
    return "theta_i = " + std::to_string(s.theta_i) + " is outside [0, pi/2]";
  }
  if (!(s.theta_e >= -kAngleSlack && s.theta_e <= kPiFloat / 2 + kAngleSlack)) {
    return "theta_e = " + std::to_string(s.theta_e) + " is outside [0, pi/2]";
  }
  if (!(s.delta_phi >= -kPiFloat - kAngleSlack && s.delta_phi <= kPiFloat + kAngleSlack)) {
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

namespace {

// ForEachSampleChunk, with `on_count` told the row count before the first chunk.
uint64_t ReadSampleChunks(const std::string& path, size_t chunk_rows, const std::function<void(uint64_t)>& on_count,
                          const std::function<void(const BrdfSample*, size_t, uint64_t)>& chunk) {
  IBRDF_CHECK(chunk_rows > 0);
  // The header decides the format: the current dtype, else version 1 (no per-channel validity: every
  // channel valid, exposures not recorded). Any other dtype gets the message of the current format.
  std::vector<size_t> shape;
  std::ifstream in;
  uint64_t count = 0;
  bool version1 = false;
  try {
    count = internal::OpenNpy(path, BrdfSampleDtype(), sizeof(BrdfSample), &shape, &in);
  } catch (const Error&) {
    const std::exception_ptr current = std::current_exception();
    try {
      in = std::ifstream();
      count = internal::OpenNpy(path, BrdfSampleDtypeVersion1(), sizeof(BrdfSampleVersion1), &shape, &in);
      version1 = true;
    } catch (const Error&) {
      std::rethrow_exception(current);
    }
  }
  if (shape.size() != 1) ThrowError(path, "sample files are one-dimensional arrays");
  if (on_count) on_count(count);
  // The rows go through a buffer of `chunk_rows` rows, read and checked there.
  const size_t row_bytes = version1 ? sizeof(BrdfSampleVersion1) : sizeof(BrdfSample);
  const uint64_t buffer_rows = std::min<uint64_t>(chunk_rows, count);
  std::vector<unsigned char> raw(buffer_rows * row_bytes);
  std::vector<BrdfSample> converted(version1 ? buffer_rows : 0);
  for (uint64_t first = 0; first < count; first += chunk_rows) {
    const uint64_t rows = std::min<uint64_t>(chunk_rows, count - first);
    internal::ReadNpyData(path, &in, raw.data(), rows * row_bytes);
    const BrdfSample* rows_read = reinterpret_cast<const BrdfSample*>(raw.data());
    if (version1) {
      for (uint64_t i = 0; i < rows; ++i) {
        std::memcpy(static_cast<void*>(&converted[i]), raw.data() + i * row_bytes, sizeof(BrdfSampleVersion1));
        converted[i].valid[0] = converted[i].valid[1] = converted[i].valid[2] = 1;
        converted[i].exposures = 0;
      }
      rows_read = converted.data();
    }
    for (uint64_t i = 0; i < rows; ++i) {
      if (PlausibleSample(rows_read[i])) continue;
      const std::string reason = InvalidSampleReason(rows_read[i]);
      if (!reason.empty()) ThrowError(path, "sample " + std::to_string(first + i) + ": " + reason);
    }
    chunk(rows_read, size_t(rows), first);
  }
  return count;
}

}  // namespace

SampleFileWriter::SampleFileWriter(const std::string& path) : writer_(path, BrdfSampleDtype(), sizeof(BrdfSample)) {}

uint64_t ForEachSampleChunk(const std::string& path, size_t chunk_rows,
                            const std::function<void(const BrdfSample* rows, size_t count, uint64_t first)>& chunk) {
  return ReadSampleChunks(path, chunk_rows, nullptr, chunk);
}

std::vector<BrdfSample> ReadSamples(const std::string& path) {
  // Chunks that stay in the cache, appended to memory reserved once (never zero-filled first; huge
  // pages where the kernel gives them on request). A whole-file read into a value-initialized vector
  // paid for zeroing and page-faulting the 85 MB of a demo run's samples, in each of check, compare,
  // reconstruct and report.
  std::vector<BrdfSample> samples;
  ReadSampleChunks(
      path, 8192,
      [&](uint64_t count) {
        samples.reserve(count);
        AdviseHugePages(samples.data(), count * sizeof(BrdfSample));
      },
      [&](const BrdfSample* rows, size_t count, uint64_t) { samples.insert(samples.end(), rows, rows + count); });
  return samples;
}

}  // namespace ibrdf
