#include "core/npy.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <ostream>
#include <utility>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMaxHeaderBytes = size_t(1) << 20;

std::string Header(const std::string& descr, const std::vector<size_t>& shape) {
  std::string dims;
  for (size_t d : shape) dims += std::to_string(d) + ",";
  if (shape.size() > 1) dims.pop_back();
  std::string dict = "{'descr': " + descr + ", 'fortran_order': False, 'shape': (" + dims + "), }";
  // Version 1.0: magic(6) + version(2) + header length(2) + dict, padded with spaces and a newline to
  // a multiple of 64 bytes.
  const size_t total = 10 + dict.size() + 1;
  dict.append((total + 63) / 64 * 64 - total, ' ');
  dict.push_back('\n');
  return dict;
}

// The value text of `key` in the header dict (a quoted string, a bracketed list, a parenthesized
// tuple or a bare word); throws unless the key appears exactly once.
std::string DictValue(const std::string& path, const std::string& header, const std::string& key) {
  const std::string quoted = "'" + key + "'";
  const size_t at = header.find(quoted);
  if (at == std::string::npos) ThrowError(path, ".npy header has no '" + key + "'");
  if (header.find(quoted, at + quoted.size()) != std::string::npos) {
    ThrowError(path, ".npy header names '" + key + "' more than once");
  }
  size_t i = at + quoted.size();
  while (i < header.size() && header[i] == ' ') ++i;
  if (i >= header.size() || header[i] != ':') ThrowError(path, ".npy header: no ':' after '" + key + "'");
  ++i;
  while (i < header.size() && header[i] == ' ') ++i;
  if (i >= header.size()) ThrowError(path, ".npy header ends after '" + key + "'");
  const size_t start = i;
  const char open = header[i];
  if (open == '\'' || open == '"') {
    const size_t end = header.find(open, i + 1);
    if (end == std::string::npos) ThrowError(path, ".npy header: unterminated string for '" + key + "'");
    return header.substr(start, end + 1 - start);
  }
  if (open == '[' || open == '(') {
    const char close = open == '[' ? ']' : ')';
    int depth = 0;
    for (; i < header.size(); ++i) {
      if (header[i] == open) ++depth;
      if (header[i] == close && --depth == 0) return header.substr(start, i + 1 - start);
    }
    ThrowError(path, ".npy header: unbalanced '" + std::string(1, open) + "' for '" + key + "'");
  }
  while (i < header.size() && header[i] != ',' && header[i] != '}') ++i;
  std::string word = header.substr(start, i - start);
  while (!word.empty() && word.back() == ' ') word.pop_back();
  return word;
}

// "(3, 4)" or "(5,)" or "()" to dimensions; digits only, no overflow.
std::vector<size_t> ParseShape(const std::string& path, const std::string& text) {
  if (text.size() < 2 || text.front() != '(' || text.back() != ')') {
    ThrowError(path, ".npy header: shape must be a tuple, got " + text);
  }
  std::vector<size_t> shape;
  size_t i = 1;
  const size_t end = text.size() - 1;
  while (i < end) {
    while (i < end && text[i] == ' ') ++i;
    if (i == end) break;
    if (!(text[i] >= '0' && text[i] <= '9')) ThrowError(path, ".npy header: bad shape " + text);
    size_t value = 0;
    for (; i < end && text[i] >= '0' && text[i] <= '9'; ++i) {
      const size_t digit = size_t(text[i] - '0');
      if (value > (std::numeric_limits<size_t>::max() - digit) / 10) {
        ThrowError(path, ".npy header: a dimension of shape " + text + " is too large");
      }
      value = value * 10 + digit;
    }
    shape.push_back(value);
    while (i < end && text[i] == ' ') ++i;
    if (i < end && text[i] != ',') ThrowError(path, ".npy header: bad shape " + text);
    if (i < end) ++i;
  }
  return shape;
}

// The 10-byte prefix of a version 1.0 file whose header dict is `header`.
void WritePrefix(std::ostream& out, const std::string& header) {
  const char prefix[10] = {'\x93',
                           'N',
                           'U',
                           'M',
                           'P',
                           'Y',
                           1,
                           0,
                           static_cast<char>(header.size() & 0xff),
                           static_cast<char>(header.size() >> 8)};
  out.write(prefix, 10);
}

}  // namespace

NpyRowWriter::NpyRowWriter(std::string path, std::string descr, size_t item_size)
    : path_(std::move(path)), descr_(std::move(descr)), item_size_(item_size) {
  IBRDF_CHECK(item_size_ > 0);
  const std::string header = Header(descr_, {0});
  // The count is patched in place at Finish(), so the header may not grow with its digits.
  IBRDF_CHECK(header.size() == Header(descr_, {size_t(9999999999999999999ull)}).size())
      << path_ << ": the .npy header of " << descr_ << " changes length with the row count";
  IBRDF_CHECK(header.size() <= 0xffff) << path_ << ": .npy header too long";
  header_bytes_ = header.size();
  out_.open(path_, std::ios::binary | std::ios::trunc);
  if (!out_) ThrowError(path_, "cannot write file");
  WritePrefix(out_, header);
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  if (!out_) ThrowError(path_, "write failed (disk full?)");
}

void NpyRowWriter::Append(const void* data, uint64_t rows) {
  IBRDF_CHECK(out_.is_open()) << path_ << ": append after Finish";
  if (rows == 0) return;
  out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(rows * item_size_));
  if (!out_) ThrowError(path_, "write failed (disk full?)");
  rows_ += rows;
}

void NpyRowWriter::Finish() {
  IBRDF_CHECK(out_.is_open()) << path_ << ": Finish called twice";
  IBRDF_CHECK(rows_ <= 9999999999999999999ull) << path_ << ": too many rows";
  const std::string header = Header(descr_, {size_t(rows_)});
  IBRDF_CHECK(header.size() == header_bytes_);
  out_.seekp(10);
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  out_.close();
  if (!out_) ThrowError(path_, "write failed (disk full?)");
}

void WriteNpy(const std::string& path, const std::string& descr, const std::vector<size_t>& shape, size_t item_size,
              const void* data, size_t bytes) {
  size_t count = 1;
  for (size_t d : shape) count *= d;
  IBRDF_CHECK(count * item_size == bytes) << path << ": shape holds " << count << " items, data " << bytes << " bytes";
  const std::string header = Header(descr, shape);
  IBRDF_CHECK(header.size() <= 0xffff) << path << ": .npy header too long";
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot write file");
    WritePrefix(out, header);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
    if (!out) ThrowError(path, "write failed (disk full?)");
  }
  file.Commit();
}

namespace internal {

uint64_t OpenNpy(const std::string& path, const std::string& descr, size_t item_size, std::vector<size_t>* shape,
                 std::ifstream* in_ptr) {
  IBRDF_CHECK(item_size > 0);
  RequireFile(path, ".npy file");
  std::ifstream& in = *in_ptr;
  in.open(path, std::ios::binary);
  if (!in) ThrowError(path, "cannot open file");
  in.seekg(0, std::ios::end);
  const uint64_t file_bytes = static_cast<uint64_t>(in.tellg());
  in.seekg(0);
  char prefix[10];
  if (!in.read(prefix, 10) || std::memcmp(prefix, kMagic, 6) != 0) {
    ThrowError(path, "not a NumPy .npy file (bad magic)");
  }
  const auto byte = [](char c) { return static_cast<uint64_t>(static_cast<unsigned char>(c)); };
  uint64_t header_length = 0;
  uint64_t prefix_length = 10;
  if (prefix[6] == 1) {
    header_length = byte(prefix[8]) | (byte(prefix[9]) << 8);
  } else if (prefix[6] == 2 || prefix[6] == 3) {
    char more[2];
    if (!in.read(more, 2)) ThrowError(path, "truncated .npy header");
    header_length = byte(prefix[8]) | (byte(prefix[9]) << 8) | (byte(more[0]) << 16) | (byte(more[1]) << 24);
    prefix_length = 12;
  } else {
    ThrowError(path, "unsupported .npy version " + std::to_string(int(prefix[6])));
  }
  if (header_length > kMaxHeaderBytes || prefix_length + header_length > file_bytes) {
    ThrowError(path, "the .npy header length " + std::to_string(header_length) + " exceeds the file (" +
                         std::to_string(file_bytes) + " bytes) or 1 MiB");
  }
  std::string header(header_length, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(header_length))) ThrowError(path, "truncated .npy header");
  const std::string found_descr = DictValue(path, header, "descr");
  if (found_descr != descr) ThrowError(path, "expected dtype " + descr + ", the file holds " + found_descr);
  const std::string order = DictValue(path, header, "fortran_order");
  if (order != "False") ThrowError(path, "expected a C-order array ('fortran_order': False), got " + order);
  *shape = ParseShape(path, DictValue(path, header, "shape"));
  uint64_t count = 1;
  for (size_t d : *shape) {
    if (d != 0 && count > std::numeric_limits<uint64_t>::max() / d) {
      ThrowError(path, "the shape's element count overflows");
    }
    count *= d;
  }
  const uint64_t available = file_bytes - prefix_length - header_length;
  // Divide rather than multiply: a lying shape could overflow the product.
  if (available % item_size != 0 || available / item_size != count) {
    ThrowError(path, "the header's shape holds " + std::to_string(count) + " items of " + std::to_string(item_size) +
                         " bytes but the file holds " + std::to_string(available) + " bytes of data");
  }
  return count;
}

void ReadNpyData(const std::string& path, std::ifstream* in, void* data, uint64_t bytes) {
  if (bytes > 0 && !in->read(static_cast<char*>(data), static_cast<std::streamsize>(bytes))) {
    ThrowError(path, "read failed");
  }
}

}  // namespace internal

void WriteNpyArray(const std::string& path, const std::vector<double>& data, const std::vector<size_t>& shape) {
  WriteNpy(path, "'<f8'", shape, sizeof(double), data.data(), data.size() * sizeof(double));
}

void WriteNpyArray(const std::string& path, const std::vector<float>& data, const std::vector<size_t>& shape) {
  WriteNpy(path, "'<f4'", shape, sizeof(float), data.data(), data.size() * sizeof(float));
}

std::vector<double> ReadNpyArray(const std::string& path, std::vector<size_t>* shape, bool require_finite) {
  std::vector<double> data = ReadNpy<double>(path, "'<f8'", shape);
  if (require_finite) {
    for (size_t i = 0; i < data.size(); ++i) {
      if (!std::isfinite(data[i])) ThrowError(path, "element " + std::to_string(i) + " is not finite");
    }
  }
  return data;
}

}  // namespace ibrdf
