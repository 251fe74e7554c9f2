#include "scan/ply_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParseType(const std::string& name, PlyType* type) {
  static const std::pair<const char*, PlyType> kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [type_name, value] : kTypes) {
    if (name == type_name) {
      *type = value;
      return true;
    }
  }
  return false;
}

int TypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool IsInteger(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

struct Property {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;  // lists only
  PlyType type = PlyType::kFloat32;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  int header_line = 0;
};

enum class Format { kAscii, kBinaryLittle, kBinaryBig };

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  int num_cols = -1, num_rows = -1;  // obj_info of Cyberware range images
  size_t body_offset = 0;
};

std::string ReadWholeFile(const std::string& path) {
  RequireFile(path, "scan file");
  // Bounded before reading: the whole file is held in memory.
  constexpr uintmax_t kMaxPlyBytes = uintmax_t(8) << 30;
  std::error_code size_error;
  const uintmax_t bytes = std::filesystem::file_size(path, size_error);
  if (size_error || bytes > kMaxPlyBytes) {
    ThrowError(path, size_error ? "cannot read the file's size"
                                : "is " + std::to_string(bytes) + " bytes; PLY files are read up to 8 GiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "cannot open for reading");
  // Read in one piece into a string of the file's size (a growing string stream copied a 400 k-face
  // mesh several times into fresh memory: most of derender's page faults on such a mesh).
  std::string data(size_t(bytes), '\0');
  in.read(data.data(), std::streamsize(bytes));
  if (in.bad()) ThrowError(path, "cannot read the file");
  data.resize(size_t(in.gcount()));
  return data;
}

std::vector<std::string> Split(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  std::string word;
  while (in >> word) words.push_back(word);
  return words;
}

bool ParseCount(const std::string& text, uint64_t* value) {
  if (text.empty() || text[0] == '-') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (errno != 0 || *end != '\0') return false;
  *value = v;
  return true;
}

Header ParseHeader(const std::string& data, const std::string& path) {
  if (data.empty()) ThrowError(path, "empty file (expected a PLY header starting with 'ply')");
  Header header;
  size_t pos = 0;
  int line_number = 0;
  bool saw_format = false, saw_end = false;
  auto where = [&](int line) { return path + ": header line " + std::to_string(line); };
  while (pos < data.size()) {
    const size_t end = data.find('\n', pos);
    if (end == std::string::npos) break;
    std::string line = data.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) {
      if (line != "ply") ThrowError(path, "not a PLY file (the first line is not 'ply')");
      continue;
    }
    const std::vector<std::string> words = Split(line);
    if (words.empty()) continue;
    const std::string& keyword = words[0];
    if (keyword == "format") {
      if (words.size() != 3 || words[2] != "1.0") ThrowError(where(line_number), "expected 'format <type> 1.0'");
      if (words[1] == "ascii") {
        header.format = Format::kAscii;
      } else if (words[1] == "binary_little_endian") {
        header.format = Format::kBinaryLittle;
      } else if (words[1] == "binary_big_endian") {
        header.format = Format::kBinaryBig;
      } else {
        ThrowError(where(line_number), "unknown format '" + words[1] + "'");
      }
      saw_format = true;
    } else if (keyword == "comment") {
      continue;
    } else if (keyword == "obj_info") {
      if (words.size() >= 3 && (words[1] == "num_cols" || words[1] == "num_rows")) {
        uint64_t v = 0;
        if (!ParseCount(words[2], &v) || v > 1000000) ThrowError(where(line_number), "bad " + words[1]);
        (words[1] == "num_cols" ? header.num_cols : header.num_rows) = static_cast<int>(v);
      }
    } else if (keyword == "element") {
      Element element;
      if (words.size() != 3 || !ParseCount(words[2], &element.count)) {
        ThrowError(where(line_number), "expected 'element <name> <count>'");
      }
      element.name = words[1];
      element.header_line = line_number;
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) ThrowError(where(line_number), "property before any element");
      Property property;
      if (words.size() == 5 && words[1] == "list") {
        property.is_list = true;
        if (!ParseType(words[2], &property.count_type) || !IsInteger(property.count_type)) {
          ThrowError(where(line_number), "list count type '" + words[2] + "' is not an integer type");
        }
        if (!ParseType(words[3], &property.type)) ThrowError(where(line_number), "unknown type '" + words[3] + "'");
        property.name = words[4];
      } else if (words.size() == 3) {
        if (!ParseType(words[1], &property.type)) ThrowError(where(line_number), "unknown type '" + words[1] + "'");
        property.name = words[2];
      } else {
        ThrowError(where(line_number), "expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      header.elements.back().properties.push_back(property);
    } else if (keyword == "end_header") {
      saw_end = true;
      break;
    } else {
      ThrowError(where(line_number), "unknown header line '" + keyword + "'");
    }
  }
  if (!saw_end) ThrowError(path, "the header has no end_header line (truncated file?)");
  if (!saw_format) ThrowError(path, "the header has no format line");
  header.body_offset = pos;
  return header;
}

// Reads the values of one element instance, whichever the format.
class BodyReader {
 public:
  BodyReader(const std::string& data, const Header& header, const std::string& path)
      : data_(data), format_(header.format), pos_(header.body_offset), path_(path) {}

  // Starts an instance (ASCII: one line). Returns false at the end of the data.
  bool BeginInstance() {
    if (format_ != Format::kAscii) return pos_ < data_.size();
    // Skip blank lines.
    while (pos_ < data_.size()) {
      size_t end = data_.find('\n', pos_);
      if (end == std::string::npos) end = data_.size();
      line_begin_ = pos_;
      line_end_ = end;
      pos_ = std::min(end + 1, data_.size());
      cursor_ = line_begin_;
      SkipSpaces();
      if (cursor_ < line_end_) return true;
    }
    return false;
  }

  // True if the current ASCII line has unread values.
  bool LineHasMore() {
    SkipSpaces();
    return cursor_ < line_end_;
  }

  bool Read(PlyType type, double* value) {
    if (format_ == Format::kAscii) return ReadAscii(type, value);
    const int size = TypeSize(type);
    if (pos_ + size > data_.size()) return false;
    unsigned char bytes[8];
    std::memcpy(bytes, data_.data() + pos_, size);
    pos_ += size;
    if (format_ == Format::kBinaryBig) std::reverse(bytes, bytes + size);
    switch (type) {
      case PlyType::kInt8:
        *value = static_cast<int8_t>(bytes[0]);
        break;
      case PlyType::kUint8:
        *value = bytes[0];
        break;
      case PlyType::kInt16: {
        int16_t v;
        std::memcpy(&v, bytes, 2);
        *value = v;
        break;
      }
      case PlyType::kUint16: {
        uint16_t v;
        std::memcpy(&v, bytes, 2);
        *value = v;
        break;
      }
      case PlyType::kInt32: {
        int32_t v;
        std::memcpy(&v, bytes, 4);
        *value = v;
        break;
      }
      case PlyType::kUint32: {
        uint32_t v;
        std::memcpy(&v, bytes, 4);
        *value = v;
        break;
      }
      case PlyType::kFloat32: {
        float v;
        std::memcpy(&v, bytes, 4);
        *value = v;
        break;
      }
      case PlyType::kFloat64: {
        double v;
        std::memcpy(&v, bytes, 8);
        *value = v;
        break;
      }
    }
    return true;
  }

  // True if anything but white space is left after the last element.
  bool HasTrailingData() {
    if (format_ != Format::kAscii) return pos_ < data_.size();
    for (size_t i = pos_; i < data_.size(); ++i) {
      if (!std::isspace(static_cast<unsigned char>(data_[i]))) return true;
    }
    return false;
  }

  bool ascii() const { return format_ == Format::kAscii; }

  // The bytes after the current position.
  size_t RemainingBytes() const { return data_.size() - std::min(pos_, data_.size()); }

 private:
  void SkipSpaces() {
    while (cursor_ < line_end_ && std::isspace(static_cast<unsigned char>(data_[cursor_]))) ++cursor_;
  }

  bool ReadAscii(PlyType type, double* value) {
    SkipSpaces();
    if (cursor_ >= line_end_) return false;
    size_t end = cursor_;
    while (end < line_end_ && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
    token_.assign(data_, cursor_, end - cursor_);
    cursor_ = end;
    char* parse_end = nullptr;
    if (IsInteger(type)) {
      errno = 0;
      const long long v = std::strtoll(token_.c_str(), &parse_end, 10);
      if (errno != 0 || *parse_end != '\0') {
        ThrowError(path_, "'" + token_ + "' is not an integer" + Context());
      }
      *value = static_cast<double>(v);
    } else {
      *value = std::strtod(token_.c_str(), &parse_end);
      if (*parse_end != '\0' || parse_end == token_.c_str()) {
        ThrowError(path_, "'" + token_ + "' is not a number" + Context());
      }
    }
    return true;
  }

 public:
  std::string Context() const {
    if (format_ != Format::kAscii) return " (byte " + std::to_string(pos_) + ")";
    size_t line = 1;
    for (size_t i = 0; i < line_begin_ && i < data_.size(); ++i) line += data_[i] == '\n';
    return " (line " + std::to_string(line) + ")";
  }

 private:
  const std::string& data_;
  Format format_;
  size_t pos_;
  size_t line_begin_ = 0, line_end_ = 0, cursor_ = 0;
  std::string token_;
  const std::string& path_;
};

int FindProperty(const Element& element, const char* name) {
  for (size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// Which of an element's properties ReadPly keeps (-1: absent), and what the element is.
struct ElementLayout {
  bool is_vertex = false, is_face = false, is_grid = false;
  std::string what;  // "vertices" or "<name> entries", for messages
  int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, ilist = -1;
  int iquality = -1, ineighbours = -1, ihull = -1;  // the scan stage's fit quality (WritePly)
};

// The values of one element instance that ReadPly keeps.
struct InstanceValues {
  double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0}, quality = 0, neighbours = 0, hull = 0;
  std::vector<int> list;  // vertex_indices
};

// Finds the properties of `element` and prepares `mesh` for it (reserves vertices, sizes the grid).
ElementLayout PrepareElement(const Element& element, const Header& header, const std::string& path, bool* have_grid,
                             ScanMesh* mesh) {
  ElementLayout layout;
  layout.what = element.name == "vertex" ? "vertices" : element.name + " entries";
  layout.is_vertex = element.name == "vertex";
  layout.is_face = element.name == "face";
  layout.is_grid = element.name == "range_grid";
  if (layout.is_vertex) {
    if (!mesh->points.empty()) ThrowError(path, "more than one vertex element");
    layout.ix = FindProperty(element, "x");
    layout.iy = FindProperty(element, "y");
    layout.iz = FindProperty(element, "z");
    if (layout.ix < 0 || layout.iy < 0 || layout.iz < 0)
      ThrowError(path, "the vertex element needs properties x, y and z");
    layout.inx = FindProperty(element, "nx");
    layout.iny = FindProperty(element, "ny");
    layout.inz = FindProperty(element, "nz");
    if (!(layout.inx >= 0 && layout.iny >= 0 && layout.inz >= 0)) layout.inx = layout.iny = layout.inz = -1;
    layout.iquality = FindProperty(element, "quality");
    layout.ineighbours = FindProperty(element, "fit_neighbours");
    layout.ihull = FindProperty(element, "hull_distance");
    if (element.count > 500000000ull) ThrowError(path, "implausible vertex count " + std::to_string(element.count));
    mesh->points.reserve(element.count);
    if (layout.inx >= 0) mesh->normals.reserve(element.count);
  }
  if (layout.is_face || layout.is_grid) {
    layout.ilist = FindProperty(element, "vertex_indices");
    if (layout.ilist < 0) layout.ilist = FindProperty(element, "vertex_index");
    if (layout.ilist < 0 || !element.properties[layout.ilist].is_list ||
        !IsInteger(element.properties[layout.ilist].type)) {
      ThrowError(path, "the " + element.name + " element needs an integer list 'vertex_indices'");
    }
  }
  if (layout.is_grid) {
    if (*have_grid) ThrowError(path, "more than one range_grid element");
    if (header.num_cols <= 0 || header.num_rows <= 0) {
      ThrowError(path, "a range_grid element needs 'obj_info num_cols' and 'obj_info num_rows' in the header");
    }
    if (element.count != static_cast<uint64_t>(header.num_cols) * header.num_rows) {
      ThrowError(path, "range_grid has " + std::to_string(element.count) + " cells, but num_cols x num_rows is " +
                           std::to_string(header.num_cols) + " x " + std::to_string(header.num_rows));
    }
    *have_grid = true;
    mesh->grid.rows = header.num_rows;
    mesh->grid.cols = header.num_cols;
    mesh->grid.cell_point.assign(element.count, -1);
  }
  return layout;
}

// Reads instance `i` of `element` into `values` (values of properties ReadPly does not keep are read
// and dropped; `values` keeps those of the previous instance where this one has none).
// `declared`: the header's element counts, as DeclaredCounts gives them, for the messages.
void ReadInstance(const Element& element, const ElementLayout& layout, uint64_t i, const std::string& path,
                  const std::string& declared, BodyReader* reader, InstanceValues* values) {
  if (!reader->BeginInstance()) {
    ThrowError(path, "the file ends after " + std::to_string(i) + " of " + std::to_string(element.count) + " " +
                         layout.what + " (truncated, or the header's count is wrong; the header declares " +
                         declared + ")");
  }
  for (size_t p = 0; p < element.properties.size(); ++p) {
    const Property& property = element.properties[p];
    auto fail = [&] {
      ThrowError(path, "the file ends inside " + element.name + " " + std::to_string(i) + " of " +
                           std::to_string(element.count) + " (truncated, or the header's count is wrong; the header "
                           "declares " + declared + ")" + reader->Context());
    };
    double value = 0.0;
    if (!property.is_list) {
      if (!reader->Read(property.type, &value)) fail();
      const int ip = static_cast<int>(p);
      if (ip == layout.ix) values->point[0] = value;
      if (ip == layout.iy) values->point[1] = value;
      if (ip == layout.iz) values->point[2] = value;
      if (ip == layout.inx) values->normal[0] = value;
      if (ip == layout.iny) values->normal[1] = value;
      if (ip == layout.inz) values->normal[2] = value;
      if (ip == layout.iquality) values->quality = value;
      if (ip == layout.ineighbours) values->neighbours = value;
      if (ip == layout.ihull) values->hull = value;
      continue;
    }
    double count = 0.0;
    if (!reader->Read(property.count_type, &count)) fail();
    if (count < 0 || count > 1000) {
      ThrowError(path, element.name + " " + std::to_string(i) + ": bad list length " + std::to_string(count) +
                           reader->Context());
    }
    if (static_cast<int>(p) == layout.ilist) values->list.clear();
    for (int k = 0; k < static_cast<int>(count); ++k) {
      if (!reader->Read(property.type, &value)) fail();
      if (static_cast<int>(p) == layout.ilist) {
        // An index outside int (a uint32 over 2^31, an ASCII 1e12) would overflow the cast.
        if (!(value >= 0 && value <= double(std::numeric_limits<int>::max()))) {
          ThrowError(path, element.name + " " + std::to_string(i) + ": vertex index " + std::to_string(value) +
                               " is negative or too large" + reader->Context());
        }
        values->list.push_back(static_cast<int>(value));
      }
    }
  }
  if (reader->ascii() && reader->LineHasMore()) {
    ThrowError(
        path, element.name + " " + std::to_string(i) + " has more values than the header declares" + reader->Context());
  }
}

// Adds instance `i`'s values to the mesh: a vertex, a polygon (to `polygons`) or a grid cell.
void StoreInstance(const ElementLayout& layout, uint64_t i, const InstanceValues& values, const std::string& path,
                   std::vector<std::vector<int>>* polygons, ScanMesh* mesh) {
  if (layout.is_vertex) {
    // Per-vertex values must be usable: finite, the scan stage's fit quality not negative.
    if (layout.iquality >= 0 && !(values.quality >= 0 && std::isfinite(values.quality))) {
      ThrowError(path, "vertex " + std::to_string(i) + ": quality (fit RMS, metres) " + std::to_string(values.quality) +
                           " is not a finite, non-negative number");
    }
    if (layout.ineighbours >= 0 && !(values.neighbours >= 0 && values.neighbours <= 1e9)) {
      ThrowError(path, "vertex " + std::to_string(i) + ": fit_neighbours " + std::to_string(values.neighbours) +
                           " is not a count");
    }
    if (layout.ihull >= 0 && !std::isfinite(values.hull)) {
      ThrowError(path, "vertex " + std::to_string(i) + ": hull_distance is not finite");
    }
    mesh->points.emplace_back(values.point[0], values.point[1], values.point[2]);
    if (layout.inx >= 0) mesh->normals.emplace_back(values.normal[0], values.normal[1], values.normal[2]);
    if (layout.iquality >= 0) mesh->fit_rms_m.push_back(static_cast<float>(values.quality));
    if (layout.ineighbours >= 0) mesh->fit_neighbours.push_back(static_cast<int>(values.neighbours));
    if (layout.ihull >= 0) mesh->hull_distance_m.push_back(static_cast<float>(values.hull));
  } else if (layout.is_face) {
    if (values.list.size() < 3) {
      ThrowError(path, "face " + std::to_string(i) + " has " + std::to_string(values.list.size()) +
                           " vertices (at least 3 needed)");
    }
    polygons->push_back(values.list);
  } else if (layout.is_grid) {
    if (values.list.size() > 1) {
      ThrowError(path, "range_grid cell " + std::to_string(i) + " lists " + std::to_string(values.list.size()) +
                           " vertices (0 or 1 expected)");
    }
    if (!values.list.empty()) mesh->grid.cell_point[i] = values.list[0];
  }
}

// Checks the indices (faces, grid cells) and coordinates; triangulates the polygons into mesh->faces.
void FinishMesh(const std::vector<std::vector<int>>& polygons, const std::string& path, ScanMesh* mesh) {
  const int n = static_cast<int>(mesh->points.size());
  mesh->faces.reserve(mesh->faces.size() + polygons.size());  // one triangle per polygon at least
  for (size_t i = 0; i < polygons.size(); ++i) {
    for (int v : polygons[i]) {
      if (v < 0 || v >= n) {
        ThrowError(path, "face " + std::to_string(i) + " refers to vertex " + std::to_string(v) + ", but there are " +
                             std::to_string(n) + " vertices");
      }
    }
    for (size_t k = 1; k + 1 < polygons[i].size(); ++k) {
      mesh->faces.emplace_back(polygons[i][0], polygons[i][k], polygons[i][k + 1]);
    }
  }
  for (size_t c = 0; c < mesh->grid.cell_point.size(); ++c) {
    const int v = mesh->grid.cell_point[c];
    if (v >= n) {
      ThrowError(path, "range_grid cell " + std::to_string(c) + " refers to vertex " + std::to_string(v) +
                           ", but there are " + std::to_string(n) + " vertices");
    }
  }
  RequireFinitePoints(*mesh, path);
  for (size_t i = 0; i < mesh->normals.size(); ++i) {
    if (!mesh->normals[i].allFinite())
      ThrowError(path, "vertex " + std::to_string(i) + " has a NaN or infinite normal");
  }
  if (mesh->points.empty()) ThrowError(path, "no vertices");
}

// Every element count checked against the bytes that remain before anything is allocated: an instance
// takes at least its fixed-size properties' bytes (binary) or one character and a separator per
// property (ASCII). A 300-byte file declaring a 100000 x 20000 range grid is an error, not 8 GB.
void CheckCountsAgainstSize(const Header& header, size_t data_size, const std::string& path) {
  uint64_t remaining = data_size - std::min(data_size, header.body_offset) + 1;  // + 1: a final line without '\n'
  for (const Element& element : header.elements) {
    uint64_t min_bytes = 0;
    for (const Property& property : element.properties) {
      if (header.format == Format::kAscii) {
        min_bytes += 2;
      } else {
        min_bytes += static_cast<uint64_t>(TypeSize(property.is_list ? property.count_type : property.type));
      }
    }
    if (min_bytes == 0) {
      if (element.count > 0) ThrowError(path, "element '" + element.name + "' has instances but no properties");
      continue;
    }
    if (element.count > remaining / min_bytes) {
      ThrowError(path, "header line " + std::to_string(element.header_line) + ": " + std::to_string(element.count) +
                           " " + element.name + " entries need at least " + std::to_string(min_bytes) +
                           " bytes each, but only " + std::to_string(remaining) +
                           " bytes follow the header (truncated file, or a wrong count)");
    }
    remaining -= element.count * min_bytes;
  }
}

}  // namespace

// The header's element counts, "vertex 3, face 1", for messages about counts that do not match the data.
std::string DeclaredCounts(const Header& header) {
  std::string counts;
  for (const Element& element : header.elements) {
    counts += (counts.empty() ? "" : ", ") + element.name + " " + std::to_string(element.count);
  }
  return counts;
}

// Each vertex of a range grid is in exactly one cell (the Stanford and Cyberware scans list the points
// in cell order). A vertex count one off shifts the cells' bytes, and the cells after the first few
// read in step again: the byte count can come out even while cells go empty, which this catches.
void CheckGridHoldsEveryVertex(const ScanMesh& mesh, const std::string& path, const std::string& declared) {
  const size_t held = static_cast<size_t>(
      std::count_if(mesh.grid.cell_point.begin(), mesh.grid.cell_point.end(), [](int v) { return v >= 0; }));
  if (held != mesh.points.size()) {
    ThrowError(path, std::to_string(held) + " of the " + std::to_string(mesh.grid.cell_point.size()) +
                         " range_grid cells hold a vertex, but there are " + std::to_string(mesh.points.size()) +
                         " vertices (each is in one cell): the header declares " + declared +
                         ", which the data does not match");
  }
}

ScanMesh ReadPly(const std::string& path) {
  const std::string data = ReadWholeFile(path);
  const Header header = ParseHeader(data, path);
  CheckCountsAgainstSize(header, data.size(), path);
  ScanMesh mesh;
  BodyReader reader(data, header, path);
  bool have_grid = false;
  std::vector<std::vector<int>> polygons;
  const std::string declared = DeclaredCounts(header);
  for (const Element& element : header.elements) {
    if (element.name == "face") polygons.reserve(size_t(element.count));
    const ElementLayout layout = PrepareElement(element, header, path, &have_grid, &mesh);
    InstanceValues values;
    for (uint64_t i = 0; i < element.count; ++i) {
      ReadInstance(element, layout, i, path, declared, &reader, &values);
      StoreInstance(layout, i, values, path, &polygons, &mesh);
    }
  }
  if (reader.HasTrailingData()) {
    ThrowError(path, (reader.ascii() ? std::string("data") : std::to_string(reader.RemainingBytes()) + " bytes") +
                         " after the last element: the header's counts are wrong (the header declares " + declared +
                         ")" + reader.Context());
  }
  if (have_grid) CheckGridHoldsEveryVertex(mesh, path, declared);
  FinishMesh(polygons, path, &mesh);
  return mesh;
}

void WritePly(const std::string& path, const ScanMesh& mesh) {
  WritePly(path, mesh, {}, "ibrdf scan (lengths in metres)");
}

void WritePly(const std::string& path, const ScanMesh& mesh, const std::vector<PlyVertexProperty>& extra,
              const std::string& comment) {
  const size_t n = mesh.points.size();
  const bool normals = mesh.normals.size() == n && n > 0;
  const bool rms = mesh.fit_rms_m.size() == n && n > 0;
  const bool neighbours = mesh.fit_neighbours.size() == n && n > 0;
  const bool hull = mesh.hull_distance_m.size() == n && n > 0;
  for (const PlyVertexProperty& property : extra) {
    if (property.values.size() != n) {
      throw InternalError(path + ": vertex property " + property.name + " has " +
                          std::to_string(property.values.size()) + " values for " + std::to_string(n) + " vertices");
    }
  }
  const auto type_name = [](PlyPropertyType type) -> const char* {
    switch (type) {
      case PlyPropertyType::kUchar: return "uchar";
      case PlyPropertyType::kInt: return "int";
      case PlyPropertyType::kFloat: return "float";
    }
    UnhandledKind("PlyPropertyType", int(type));
  };
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot open for writing");
    out << "ply\nformat binary_little_endian 1.0\ncomment " << comment << "\n";
    out << "element vertex " << n << "\nproperty double x\nproperty double y\nproperty double z\n";
    if (normals) out << "property float nx\nproperty float ny\nproperty float nz\n";
    if (rms) out << "property float quality\n";
    if (neighbours) out << "property int fit_neighbours\n";
    if (hull) out << "property float hull_distance\n";
    for (const PlyVertexProperty& property : extra) {
      out << "property " << type_name(property.type) << " " << property.name << "\n";
    }
    out << "element face " << mesh.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
    static_assert(sizeof(float) == 4 && sizeof(int32_t) == 4, "PLY sizes");
    auto put = [&out](const auto& value) { out.write(reinterpret_cast<const char*>(&value), sizeof(value)); };
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) put(mesh.points[i][k]);
      if (normals) {
        for (int k = 0; k < 3; ++k) put(static_cast<float>(mesh.normals[i][k]));
      }
      if (rms) put(mesh.fit_rms_m[i]);
      if (neighbours) put(static_cast<int32_t>(mesh.fit_neighbours[i]));
      if (hull) put(mesh.hull_distance_m[i]);
      for (const PlyVertexProperty& property : extra) {
        const double v = property.values[i];
        switch (property.type) {
          case PlyPropertyType::kUchar:
            put(static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)));
            break;
          case PlyPropertyType::kInt:
            put(static_cast<int32_t>(std::lround(v)));
            break;
          case PlyPropertyType::kFloat:
            put(static_cast<float>(v));
            break;
        }
      }
    }
    for (const Eigen::Vector3i& f : mesh.faces) {
      put(static_cast<uint8_t>(3));
      for (int k = 0; k < 3; ++k) put(static_cast<int32_t>(f[k]));
    }
    out.flush();
    if (!out) ThrowError(path, "write failed (disk full?)");
  }
  file.Commit();
}

}  // namespace ibrdf
