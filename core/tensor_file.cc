#include "core/tensor_file.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

constexpr char kMagic[12] = "tensor_file";  // with its terminating zero: 12 bytes

template <typename T>
void AppendValue(std::vector<char>* out, T value) {
  const char* p = reinterpret_cast<const char*>(&value);
  out->insert(out->end(), p, p + sizeof(T));
}

}  // namespace

size_t TensorTypeSize(TensorType type) {
  switch (type) {
    case TensorType::kUInt8:
    case TensorType::kInt8:
      return 1;
    case TensorType::kUInt16:
    case TensorType::kInt16:
    case TensorType::kFloat16:
      return 2;
    case TensorType::kUInt32:
    case TensorType::kInt32:
    case TensorType::kFloat32:
      return 4;
    case TensorType::kUInt64:
    case TensorType::kInt64:
    case TensorType::kFloat64:
      return 8;
    default:
      return 0;
  }
}

std::string TensorTypeName(TensorType type) {
  static const char* const kNames[] = {"invalid", "uint8",  "int8",  "uint16",  "int16",   "uint32",
                                       "int32",   "uint64", "int64", "float16", "float32", "float64"};
  const auto index = static_cast<size_t>(type);
  return index < std::size(kNames) ? kNames[index] : "unknown";
}

size_t TensorField::Elements() const {
  size_t n = 1;
  for (uint64_t s : shape) n *= size_t(s);
  return n;
}

std::vector<float> TensorField::Floats() const {
  IBRDF_CHECK(dtype == TensorType::kFloat32) << "field of type " << TensorTypeName(dtype);
  std::vector<float> values(Elements());
  IBRDF_CHECK(data.size() == values.size() * sizeof(float));
  std::memcpy(values.data(), data.data(), data.size());
  return values;
}

std::string TensorField::Describe() const {
  std::ostringstream out;
  out << TensorTypeName(dtype) << " [";
  for (size_t i = 0; i < shape.size(); ++i) out << (i ? ", " : "") << shape[i];
  out << "]";
  return out.str();
}

TensorField FloatField(const std::vector<uint64_t>& shape, const std::vector<float>& values) {
  TensorField field;
  field.dtype = TensorType::kFloat32;
  field.shape = shape;
  IBRDF_CHECK(field.Elements() == values.size()) << field.Elements() << " vs " << values.size();
  field.data.resize(values.size() * sizeof(float));
  std::memcpy(field.data.data(), values.data(), field.data.size());
  return field;
}

TensorField BytesField(const std::vector<uint8_t>& bytes) {
  TensorField field;
  field.dtype = TensorType::kUInt8;
  field.shape = {bytes.size()};
  field.data = bytes;
  return field;
}

TensorField TextField(const std::string& text) { return BytesField(std::vector<uint8_t>(text.begin(), text.end())); }

TensorFile ReadTensorFile(const std::string& path) {
  // The header is parsed from the stream and each field's data read straight into the field (no copy
  // of the whole file in memory).
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "cannot open the tensor file");
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) ThrowError(path, "cannot read the tensor file's size");
  const size_t size = static_cast<size_t>(end);
  in.seekg(0);
  size_t pos = 0, stream_pos = 0;  // where the next read starts; where the stream stands
  // Reads `count` bytes at `pos` (advancing it); false when they run past the end of the file.
  auto read = [&](void* out, size_t count) {
    if (pos + count > size) return false;
    if (stream_pos != pos) in.seekg(std::streamoff(pos));
    in.read(static_cast<char*>(out), std::streamsize(count));
    if (!in) ThrowError(path, "read failed at byte " + std::to_string(pos));
    pos += count;
    stream_pos = pos;
    return true;
  };
  auto value = [&](auto* v) { return read(v, sizeof(*v)); };
  char magic[12];
  uint8_t version[2];
  uint32_t n_fields = 0;
  if (size < 18) ThrowError(path, "not a tensor file: " + std::to_string(size) + " bytes (truncated?)");
  read(magic, 12);
  if (std::memcmp(magic, kMagic, 12) != 0) ThrowError(path, "not a tensor file: the header is not \"tensor_file\"");
  value(&version[0]);
  value(&version[1]);
  if (version[0] != 1 || version[1] != 0) {
    ThrowError(path, "tensor file version " + std::to_string(version[0]) + "." + std::to_string(version[1]) +
                         " (expected 1.0)");
  }
  value(&n_fields);
  TensorFile file;
  for (uint32_t i = 0; i < n_fields; ++i) {
    const std::string where = path + ": field " + std::to_string(i);
    uint16_t name_length = 0, rank = 0;
    uint8_t dtype = 0;
    uint64_t offset = 0;
    if (!value(&name_length) || pos + name_length > size) ThrowError(where, "truncated field header");
    std::string name(name_length, '\0');
    read(name.data(), name_length);
    if (!value(&rank) || !value(&dtype) || !value(&offset)) {
      ThrowError(where + " \"" + name + "\"", "truncated field header");
    }
    TensorField field;
    field.dtype = static_cast<TensorType>(dtype);
    if (TensorTypeSize(field.dtype) == 0) {
      ThrowError(where + " \"" + name + "\"", "unknown dtype code " + std::to_string(dtype) + " (expected 1 to 11)");
    }
    field.shape.resize(rank);
    // Overflow-safe size: every dimension and the product stay within the file's size.
    uint64_t total = TensorTypeSize(field.dtype);
    for (uint16_t d = 0; d < rank; ++d) {
      if (!value(&field.shape[d])) ThrowError(where + " \"" + name + "\"", "truncated shape");
      if (field.shape[d] != 0 && total > size / field.shape[d])
        total = size + 1;
      else
        total *= field.shape[d];
    }
    if (offset > size || total > size - offset) {
      ThrowError(where + " \"" + name + "\"", field.Describe() + " at offset " + std::to_string(offset) +
                                                  " runs past the end of the file (" + std::to_string(size) +
                                                  " bytes; truncated?)");
    }
    if (file.count(name)) ThrowError(where, "duplicate field \"" + name + "\"");
    // The data in place; the header continues after the shape.
    const size_t header_pos = pos;
    field.data.resize(size_t(total));
    pos = size_t(offset);
    read(field.data.data(), size_t(total));
    pos = header_pos;
    file.emplace(name, std::move(field));
  }
  return file;
}

void WriteTensorFile(const std::string& path, const TensorFile& fields) {
  // Header size first, then the data at 8-byte aligned offsets.
  size_t header = 12 + 2 + 4;
  for (const auto& [name, field] : fields) header += 2 + name.size() + 2 + 1 + 8 + 8 * field.shape.size();
  std::vector<uint64_t> offsets;
  uint64_t offset = (header + 7) / 8 * 8;
  for (const auto& [name, field] : fields) {
    IBRDF_CHECK(field.data.size() == field.Elements() * TensorTypeSize(field.dtype)) << name;
    offsets.push_back(offset);
    offset = (offset + field.data.size() + 7) / 8 * 8;
  }
  std::vector<char> out;
  out.reserve(offset);
  out.insert(out.end(), kMagic, kMagic + 12);
  AppendValue<uint8_t>(&out, 1);
  AppendValue<uint8_t>(&out, 0);
  AppendValue<uint32_t>(&out, uint32_t(fields.size()));
  size_t i = 0;
  for (const auto& [name, field] : fields) {
    AppendValue<uint16_t>(&out, uint16_t(name.size()));
    out.insert(out.end(), name.begin(), name.end());
    AppendValue<uint16_t>(&out, uint16_t(field.shape.size()));
    AppendValue<uint8_t>(&out, static_cast<uint8_t>(field.dtype));
    AppendValue<uint64_t>(&out, offsets[i++]);
    for (uint64_t s : field.shape) AppendValue<uint64_t>(&out, s);
  }
  i = 0;
  for (const auto& [name, field] : fields) {
    out.resize(offsets[i++], 0);
    out.insert(out.end(), field.data.begin(), field.data.end());
  }
  out.resize(offset, 0);
  AtomicFile file(path);
  {
    std::ofstream stream(file.temporary_path(), std::ios::binary);
    stream.write(out.data(), std::streamsize(out.size()));
    if (!stream) ThrowError(path, "write failed");
  }
  file.Commit();
}

const TensorField& RequireField(const TensorFile& file, const std::string& path, const std::string& name,
                                TensorType dtype, size_t rank) {
  const auto it = file.find(name);
  if (it == file.end()) ThrowError(path, "missing field \"" + name + "\"");
  if (it->second.dtype != dtype || it->second.shape.size() != rank) {
    ThrowError(path + ": field \"" + name + "\"", "is " + it->second.Describe() + ", expected " +
                                                      TensorTypeName(dtype) + " of rank " + std::to_string(rank));
  }
  return it->second;
}

}  // namespace ibrdf
