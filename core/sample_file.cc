#include "core/sample_file.h"

#include <cstring>
#include <fstream>
#include <regex>
#include <stdexcept>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {
constexpr char kMagic[] = "\x93NUMPY";

std::string Header(size_t rows) {
  std::string dict = std::string("{'descr': ") + BrdfSampleDtype() +
                     ", 'fortran_order': False, 'shape': (" + std::to_string(rows) + ",), }";
  // Version 1.0: magic(6) + version(2) + header length(2) + dict, padded with spaces and a newline
  // to a multiple of 64 bytes.
  const size_t prefix = 10;
  size_t total = prefix + dict.size() + 1;
  const size_t padded = (total + 63) / 64 * 64;
  dict.append(padded - total, ' ');
  dict.push_back('\n');
  return dict;
}
}  // namespace

const char* BrdfSampleDtype() {
  return "[('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), ('theta_e', '<f4'), "
         "('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), ('image', '<u4'), "
         "('pixel', '<u4', (2,))]";
}

std::string SidecarPath(const std::string& samples_path) { return samples_path + ".json"; }

void WriteSamples(const std::string& path, const std::vector<BrdfSample>& samples) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot write file");
    const std::string header = Header(samples.size());
    const uint16_t header_length = static_cast<uint16_t>(header.size());
    out.write(kMagic, 6);
    const char version[2] = {1, 0};
    out.write(version, 2);
    const char length[2] = {static_cast<char>(header_length & 0xff), static_cast<char>(header_length >> 8)};
    out.write(length, 2);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(reinterpret_cast<const char*>(samples.data()),
              static_cast<std::streamsize>(samples.size() * sizeof(BrdfSample)));
    if (!out) ThrowError(path, "write failed (disk full?)");
  }
  file.Commit();
}

std::vector<BrdfSample> ReadSamples(const std::string& path) {
  RequireFile(path, "sample file");
  std::ifstream in(path, std::ios::binary);
  char prefix[10];
  if (!in.read(prefix, 10) || std::memcmp(prefix, kMagic, 6) != 0) {
    ThrowError(path, "not a NumPy .npy file (bad magic)");
  }
  size_t header_length = 0;
  if (prefix[6] == 1) {
    header_length = static_cast<unsigned char>(prefix[8]) | (static_cast<unsigned char>(prefix[9]) << 8);
  } else if (prefix[6] == 2 || prefix[6] == 3) {
    char more[2];
    if (!in.read(more, 2)) ThrowError(path, "truncated .npy header");
    header_length = static_cast<unsigned char>(prefix[8]) | (static_cast<unsigned char>(prefix[9]) << 8) |
                    (static_cast<unsigned char>(more[0]) << 16) | (static_cast<unsigned char>(more[1]) << 24);
  } else {
    ThrowError(path, "unsupported .npy version " + std::to_string(int(prefix[6])));
  }
  std::string header(header_length, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(header_length))) {
    ThrowError(path, "truncated .npy header");
  }
  // The dtype must be ours exactly; NumPy writes the same text for the same dtype.
  if (header.find(BrdfSampleDtype()) == std::string::npos) {
    ThrowError(path, "not an ibrdf sample file: its dtype is not " + std::string(BrdfSampleDtype()));
  }
  if (header.find("'fortran_order': False") == std::string::npos) {
    ThrowError(path, "Fortran-ordered arrays are not supported");
  }
  std::smatch match;
  if (!std::regex_search(header, match, std::regex("'shape': \\((\\d+),\\)"))) {
    ThrowError(path, "sample files are one-dimensional arrays; header: " + header);
  }
  size_t rows = 0;
  try {
    rows = std::stoull(match[1].str());
  } catch (const std::out_of_range&) {
    ThrowError(path, "the header's row count " + match[1].str() + " is too large");
  }
  const std::streampos data_start = in.tellg();
  in.seekg(0, std::ios::end);
  const size_t available = static_cast<size_t>(in.tellg() - data_start);
  // Divide rather than multiply: a lying header's row count could overflow the product.
  if (available % sizeof(BrdfSample) != 0 || available / sizeof(BrdfSample) != rows) {
    ThrowError(path, "the header says " + std::to_string(rows) + " rows of " + std::to_string(sizeof(BrdfSample)) +
                         " bytes but the file holds " + std::to_string(available) + " bytes of data");
  }
  in.seekg(data_start);
  std::vector<BrdfSample> samples(rows);
  if (!in.read(reinterpret_cast<char*>(samples.data()), static_cast<std::streamsize>(available))) {
    ThrowError(path, "read failed");
  }
  return samples;
}

}  // namespace ibrdf
