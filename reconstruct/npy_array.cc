#include "reconstruct/npy_array.h"

#include <fstream>
#include <regex>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

std::string Header(const char* descr, const std::vector<size_t>& shape) {
  std::string dims;
  for (size_t d : shape) dims += std::to_string(d) + ",";
  if (shape.size() > 1) dims.pop_back();
  std::string dict =
      std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  const size_t total = 10 + dict.size() + 1;
  dict.append((total + 63) / 64 * 64 - total, ' ');
  dict.push_back('\n');
  return dict;
}

template <class T>
void Write(const std::string& path, const std::vector<T>& data, const std::vector<size_t>& shape, const char* descr) {
  size_t count = 1;
  for (size_t d : shape) count *= d;
  IBRDF_CHECK(count == data.size()) << path << ": shape holds " << count << " elements, data " << data.size();
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot write file");
    const std::string header = Header(descr, shape);
    const char prefix[10] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0, static_cast<char>(header.size() & 0xff),
                             static_cast<char>(header.size() >> 8)};
    out.write(prefix, 10);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * sizeof(T)));
    if (!out) ThrowError(path, "write failed (disk full?)");
  }
  file.Commit();
}

}  // namespace

void WriteNpyArray(const std::string& path, const std::vector<double>& data, const std::vector<size_t>& shape) {
  Write(path, data, shape, "<f8");
}

void WriteNpyArray(const std::string& path, const std::vector<float>& data, const std::vector<size_t>& shape) {
  Write(path, data, shape, "<f4");
}

std::vector<double> ReadNpyArray(const std::string& path, std::vector<size_t>* shape) {
  RequireFile(path, "array file");
  std::ifstream in(path, std::ios::binary);
  char prefix[10];
  if (!in.read(prefix, 10) || std::string(prefix, 6) != "\x93NUMPY" || prefix[6] != 1) {
    ThrowError(path, "not a version 1.0 NumPy .npy file");
  }
  const size_t length = static_cast<unsigned char>(prefix[8]) | (static_cast<unsigned char>(prefix[9]) << 8);
  std::string header(length, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(length))) ThrowError(path, "truncated .npy header");
  if (header.find("'descr': '<f8'") == std::string::npos || header.find("'fortran_order': False") == std::string::npos) {
    ThrowError(path, "expected a C-order float64 ('<f8') array; header: " + header);
  }
  std::smatch match;
  if (!std::regex_search(header, match, std::regex("'shape': \\(([0-9, ]*)\\)"))) {
    ThrowError(path, "no shape in the .npy header");
  }
  shape->clear();
  size_t count = 1;
  const std::string dims = match[1].str();
  const std::regex number("\\d+");
  for (std::sregex_iterator it(dims.begin(), dims.end(), number), end; it != end; ++it) {
    shape->push_back(std::stoull(it->str()));
    count *= shape->back();
  }
  std::vector<double> data(count);
  if (!in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(count * sizeof(double)))) {
    ThrowError(path, "truncated: the header promises " + std::to_string(count) + " doubles");
  }
  return data;
}

}  // namespace ibrdf
