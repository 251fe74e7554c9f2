// The tensor file format of Mitsuba and of Dupuy and Jakob 2018's RGL material database (".bsdf"
// files; rgl-epfl/brdf-loader, Mitsuba 3's TensorFile, pbrt-v4's measured material read it):
//   12 bytes "tensor_file\0", 2 bytes version (1, 0), uint32 field count, then per field
//   uint16 name length, the name (UTF-8, no terminator), uint16 rank, uint8 dtype, uint64 offset of the
//   data from the start of the file, rank x uint64 shape; the data (little-endian, C order) at the
//   offsets (ibrdf aligns them to 8 bytes, as Mitsuba's writer does).
// dtype codes (Mitsuba's Struct::Type): 1 uint8, 2 int8, 3 uint16, 4 int16, 5 uint32, 6 int32,
// 7 uint64, 8 int64, 9 float16, 10 float32, 11 float64.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace ibrdf {

enum class TensorType : uint8_t {
  kInvalid = 0,
  kUInt8 = 1,
  kInt8 = 2,
  kUInt16 = 3,
  kInt16 = 4,
  kUInt32 = 5,
  kInt32 = 6,
  kUInt64 = 7,
  kInt64 = 8,
  kFloat16 = 9,
  kFloat32 = 10,
  kFloat64 = 11,
};

// Bytes per element of `type` (0 for kInvalid).
size_t TensorTypeSize(TensorType type);
// "uint8", "float32", ...
std::string TensorTypeName(TensorType type);

// One named array of a tensor file.
struct TensorField {
  TensorType dtype = TensorType::kInvalid;
  std::vector<uint64_t> shape;  // rank and size along each dimension (C order)
  std::vector<uint8_t> data;    // the raw little-endian bytes, product(shape) * TensorTypeSize(dtype)

  size_t Elements() const;
  // The data as floats; IBRDF_CHECK that dtype is float32.
  std::vector<float> Floats() const;
  // "float32 [1, 24, 64, 64]".
  std::string Describe() const;
};

// A float32 field of `shape` holding `values` (product(shape) of them).
TensorField FloatField(const std::vector<uint64_t>& shape, const std::vector<float>& values);
// A uint8 field of rank 1 holding `text`'s bytes (the RGL files' "description").
TensorField TextField(const std::string& text);
// A uint8 field of rank 1 holding `bytes`.
TensorField BytesField(const std::vector<uint8_t>& bytes);

using TensorFile = std::map<std::string, TensorField>;

// Reads a tensor file. Throws Error naming the file and what is wrong (header, version, a field's type,
// shape or data beyond the end of the file, a duplicate name).
TensorFile ReadTensorFile(const std::string& path);

// Writes `fields` (in name order) atomically: the file appears only when complete.
void WriteTensorFile(const std::string& path, const TensorFile& fields);

// The required field `name` of `file` read from `path` with the expected dtype and rank (Error naming
// the file and the field otherwise).
const TensorField& RequireField(const TensorFile& file, const std::string& path, const std::string& name,
                                TensorType dtype, size_t rank);

}  // namespace ibrdf
