// Plain N-dimensional NumPy arrays (.npy version 1.0, little-endian, C order): the export format of
// tabulated BRDFs, reliability maps and converted samples, loadable with one numpy.load.
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

// Writes `data` (row-major, of the product of `shape` elements) atomically as '<f8'.
void WriteNpyArray(const std::string& path, const std::vector<double>& data, const std::vector<size_t>& shape);
// The same as '<f4'.
void WriteNpyArray(const std::string& path, const std::vector<float>& data, const std::vector<size_t>& shape);

// Reads a '<f8' array written by WriteNpyArray (or NumPy); `shape` gets its shape. Throws Error naming
// the file on anything else.
std::vector<double> ReadNpyArray(const std::string& path, std::vector<size_t>* shape);

}  // namespace ibrdf
