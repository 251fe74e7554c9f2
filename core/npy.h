// NumPy .npy files (https://numpy.org/devdocs/reference/generated/numpy.lib.format.html): the one
// reader and writer of the tool, used by the sample files (core/sample_file.h) and by the plain
// arrays of tabulated BRDFs, reliability maps and evaluation points.
//
// The reader trusts nothing in the file: the path must be a regular file, the header at most 1 MiB,
// its dict must hold 'descr', 'fortran_order' and 'shape' exactly once each, the shape's element count
// is computed with overflow checks, and the data must be exactly count x item size bytes, all before
// anything is allocated for the data. Every failure is an Error naming the file and what is wrong.
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace ibrdf {

// Writes `bytes` bytes of little-endian, C-order data as a version 1.0 .npy with the given dtype
// description (a NumPy descr literal: '<f8' or a structured list) and shape, atomically. The shape's
// element count times `item_size` must equal `bytes` (IBRDF_CHECK).
void WriteNpy(const std::string& path, const std::string& descr, const std::vector<size_t>& shape, size_t item_size,
              const void* data, size_t bytes);

// A one-dimensional .npy of fixed-size rows written as they come, for arrays too large to hold in memory:
// the header goes first with room for any row count, rows are appended, and Finish() writes the count
// into the header in place. The file is byte for byte what WriteNpy writes for the same rows. It is
// written at `path` directly: callers write to an AtomicFile's temporary path (core/file_util.h) and
// commit it after Finish(), so the final file appears only when complete.
class NpyRowWriter {
 public:
  // IBRDF_CHECKs that `descr`'s header has the same length for any row count below 10^19 (true of
  // every dtype of the tool: the padding to 64 bytes absorbs the digits).
  NpyRowWriter(std::string path, std::string descr, size_t item_size);
  NpyRowWriter(const NpyRowWriter&) = delete;
  NpyRowWriter& operator=(const NpyRowWriter&) = delete;

  // Appends `rows` rows of item_size bytes each. Throws Error naming the file when the write fails.
  void Append(const void* data, uint64_t rows);
  uint64_t rows() const { return rows_; }
  // Writes the row count into the header and closes the file; throws Error naming the file on failure.
  void Finish();

 private:
  std::string path_, descr_;
  size_t item_size_;
  size_t header_bytes_;
  uint64_t rows_ = 0;
  std::ofstream out_;
};

namespace internal {
// Opens `path`, checks its header against `descr` and `item_size` and the data's size against the
// shape; leaves `in` at the data and returns the item count.
uint64_t OpenNpy(const std::string& path, const std::string& descr, size_t item_size, std::vector<size_t>* shape,
                 std::ifstream* in);
void ReadNpyData(const std::string& path, std::ifstream* in, void* data, uint64_t bytes);
}  // namespace internal

// Reads a .npy whose descr is exactly `descr` (as NumPy writes it; quotes included for a plain type,
// e.g. "'<f8'") and whose items are T (sizeof(T) bytes each), C order. `shape` gets its shape.
// Versions 1.0, 2.0 and 3.0 are read.
template <class T>
std::vector<T> ReadNpy(const std::string& path, const std::string& descr, std::vector<size_t>* shape) {
  std::ifstream in;
  const uint64_t count = internal::OpenNpy(path, descr, sizeof(T), shape, &in);
  std::vector<T> data(count);
  internal::ReadNpyData(path, &in, data.data(), count * sizeof(T));
  return data;
}

// Plain arrays: `data` row-major, of the product of `shape` elements, written as '<f8' or '<f4'.
void WriteNpyArray(const std::string& path, const std::vector<double>& data, const std::vector<size_t>& shape);
void WriteNpyArray(const std::string& path, const std::vector<float>& data, const std::vector<size_t>& shape);

// Reads a C-order '<f8' array; `shape` gets its shape. Throws Error naming the file on anything else,
// including NaN or infinite values when `require_finite` is set.
std::vector<double> ReadNpyArray(const std::string& path, std::vector<size_t>* shape, bool require_finite = false);

}  // namespace ibrdf
