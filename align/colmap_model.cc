#include "align/colmap_model.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/file_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// COLMAP's camera model ids, in its order.
constexpr const char* kColmapModels[] = {"SIMPLE_PINHOLE",
                                         "PINHOLE",
                                         "SIMPLE_RADIAL",
                                         "RADIAL",
                                         "OPENCV",
                                         "OPENCV_FISHEYE",
                                         "FULL_OPENCV",
                                         "FOV",
                                         "SIMPLE_RADIAL_FISHEYE",
                                         "RADIAL_FISHEYE",
                                         "THIN_PRISM_FISHEYE"};

// A little-endian binary reader that names the file and the byte offset on a short read.
class BinaryReader {
 public:
  explicit BinaryReader(std::string path) : path_(std::move(path)), in_(path_, std::ios::binary) {
    if (!in_) ThrowError(path_, "cannot open file");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<uint64_t>(in_.tellg());
    in_.seekg(0);
  }
  template <typename T>
  T Read(const char* what) {
    T value;
    if (!in_.read(reinterpret_cast<char*>(&value), sizeof(T))) {
      ThrowError(path_, std::string("truncated: cannot read ") + what + " at byte " + std::to_string(offset_));
    }
    offset_ += sizeof(T);
    return value;
  }
  // A count of following records, each at least `min_record_bytes` long: a count the rest of the
  // file cannot hold is corruption, caught before any allocation.
  uint64_t Count(const char* what, uint64_t min_record_bytes) {
    const uint64_t count = Read<uint64_t>(what);
    if (min_record_bytes > 0 && count > (size_ - offset_) / min_record_bytes) {
      ThrowError(path_, std::string("corrupt: ") + what + " " + std::to_string(count) + " at byte " +
                            std::to_string(offset_ - 8) + " does not fit in the file");
    }
    return count;
  }
  std::string ReadString(const char* what) {
    std::string s;
    char c;
    while (true) {
      if (!in_.get(c)) ThrowError(path_, std::string("truncated: unterminated ") + what);
      ++offset_;
      if (c == '\0') break;
      s.push_back(c);
      if (s.size() > 65536) ThrowError(path_, std::string("corrupt: ") + what + " longer than 64 KiB");
    }
    return s;
  }
  void ExpectEnd() {
    if (offset_ != size_) {
      ThrowError(path_, "corrupt: " + std::to_string(size_ - offset_) + " unexpected bytes after the last record");
    }
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
  uint64_t offset_ = 0;
};

Camera MakeCamera(const std::string& model_name, uint64_t width, uint64_t height, std::vector<double> params,
                  const std::string& where) {
  CameraModelId model;
  if (!CameraModelFromName(model_name, &model)) {
    ThrowError(where, "unsupported camera model " + model_name +
                          " (ibrdf reads SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL and OPENCV)");
  }
  if (width == 0 || height == 0 || width > 1000000 || height > 1000000) {
    ThrowError(where, "implausible image size " + std::to_string(width) + "x" + std::to_string(height));
  }
  return Camera::Create(model, static_cast<int>(width), static_cast<int>(height), std::move(params), where);
}

Rigid3d MakePose(double qw, double qx, double qy, double qz, double tx, double ty, double tz,
                 const std::string& where) {
  const double norm = std::sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6 || !std::isfinite(tx + ty + tz)) {
    ThrowError(where, "pose is not a unit quaternion and finite translation");
  }
  // Kept exactly as stored (no renormalization), so binary and text agree to the last digit they share.
  return Rigid3d(Eigen::Quaterniond(qw, qx, qy, qz), Eigen::Vector3d(tx, ty, tz));
}

std::string Find(const std::string& directory, const std::string& name) {
  const std::string path = (fs::path(directory) / name).string();
  if (!fs::is_regular_file(path)) ThrowError(path, "COLMAP model file does not exist");
  return path;
}

// Lines of a COLMAP text file without comments and blank lines, with their line numbers.
std::vector<std::pair<int, std::string>> DataLines(const std::string& path) {
  std::ifstream in(path);
  if (!in) ThrowError(path, "cannot open file");
  std::vector<std::pair<int, std::string>> lines;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

std::vector<std::string> Fields(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> fields;
  std::string field;
  while (in >> field) fields.push_back(field);
  return fields;
}

// Whole-token number parsing: "12x.5" or "0.1" in an integer field is an error naming the line, not 12
// or 0 (stream extraction stopped at the first bad character and std::stod threw a bare "stod").
uint64_t ParseUnsigned(const std::string& token, const std::string& where, const char* what, uint64_t max) {
  if (token.empty() || !std::isdigit(static_cast<unsigned char>(token[0]))) {
    ThrowError(where, std::string(what) + " '" + token + "' is not a non-negative integer");
  }
  errno = 0;
  char* end = nullptr;
  const unsigned long long value = std::strtoull(token.c_str(), &end, 10);
  if (*end != '\0') ThrowError(where, std::string(what) + " '" + token + "' is not a non-negative integer");
  if (errno == ERANGE || value > max) {
    ThrowError(where, std::string(what) + " " + token + " is out of range (at most " + std::to_string(max) + ")");
  }
  return value;
}

int64_t ParseSigned(const std::string& token, const std::string& where, const char* what) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(token.c_str(), &end, 10);
  if (token.empty() || *end != '\0') ThrowError(where, std::string(what) + " '" + token + "' is not an integer");
  if (errno == ERANGE) ThrowError(where, std::string(what) + " " + token + " is out of range");
  return value;
}

// A finite real number, the whole token.
double ParseReal(const std::string& token, const std::string& where, const char* what) {
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (token.empty() || *end != '\0') ThrowError(where, std::string(what) + " '" + token + "' is not a number");
  if (!std::isfinite(value)) ThrowError(where, std::string(what) + " " + token + " is not finite");
  return value;
}

// A little-endian binary writer into an AtomicFile.
class BinaryWriter {
 public:
  explicit BinaryWriter(const std::string& path) : file_(path), out_(file_.temporary_path(), std::ios::binary) {
    if (!out_) ThrowError(path, "cannot write file");
  }
  template <typename T>
  void Write(const T& value) {
    out_.write(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void WriteString(const std::string& s) { out_.write(s.c_str(), static_cast<std::streamsize>(s.size() + 1)); }
  void Commit() {
    out_.close();
    if (!out_) ThrowError(file_.final_path(), "write failed");
    file_.Commit();
  }

 private:
  AtomicFile file_;
  std::ofstream out_;
};

// A text file written through an AtomicFile, full double precision.
class TextWriter {
 public:
  explicit TextWriter(const std::string& path) : file_(path), out_(file_.temporary_path()) {
    if (!out_) ThrowError(path, "cannot write file");
    out_.precision(17);
  }
  std::ofstream& out() { return out_; }
  void Commit() {
    out_.close();
    if (!out_) ThrowError(file_.final_path(), "write failed");
    file_.Commit();
  }

 private:
  AtomicFile file_;
  std::ofstream out_;
};

void RequireDirectory(const std::string& directory) {
  if (!fs::is_directory(directory)) ThrowError(directory, "is not a folder (the COLMAP model is written into it)");
}

}  // namespace

const char* ColmapModelNameFromId(int model_id) {
  if (model_id < 0 || model_id >= static_cast<int>(std::size(kColmapModels))) return nullptr;
  return kColmapModels[model_id];
}

int ColmapModelIdFromName(const std::string& name) {
  for (int id = 0; id < static_cast<int>(std::size(kColmapModels)); ++id) {
    if (name == kColmapModels[id]) return id;
  }
  IBRDF_CHECK(false) << "not a COLMAP camera model: " << name;
  return -1;
}

ColmapModel ColmapModel::Read(const std::string& directory) {
  if (fs::exists(fs::path(directory) / "cameras.bin")) return ReadBinary(directory);
  if (fs::exists(fs::path(directory) / "cameras.txt")) return ReadText(directory);
  ThrowError(directory, "no COLMAP model here (neither cameras.bin nor cameras.txt)");
}

ColmapModel ColmapModel::ReadBinary(const std::string& directory) {
  ColmapModel model;
  {
    BinaryReader in(Find(directory, "cameras.bin"));
    const uint64_t count = in.Count("camera count", 24);
    for (uint64_t i = 0; i < count; ++i) {
      const uint32_t id = in.Read<uint32_t>("camera id");
      const int32_t model_id = in.Read<int32_t>("camera model id");
      const uint64_t width = in.Read<uint64_t>("width");
      const uint64_t height = in.Read<uint64_t>("height");
      const std::string where = in.path() + ": camera " + std::to_string(id);
      const char* name = ColmapModelNameFromId(model_id);
      if (!name) ThrowError(where, "unknown camera model id " + std::to_string(model_id));
      CameraModelId supported;
      if (!CameraModelFromName(name, &supported)) {
        ThrowError(where, std::string("unsupported camera model ") + name +
                              " (ibrdf reads SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL and OPENCV)");
      }
      std::vector<double> params(CameraModelNumParams(supported));
      for (double& p : params) {
        p = in.Read<double>("camera parameter");
        if (!std::isfinite(p)) ThrowError(where, "a camera parameter is not finite");
      }
      if (!model.cameras.emplace(id, MakeCamera(name, width, height, params, where)).second) {
        ThrowError(where, "camera id listed twice");
      }
    }
    in.ExpectEnd();
  }
  {
    BinaryReader in(Find(directory, "images.bin"));
    const uint64_t count = in.Count("image count", 76);
    for (uint64_t i = 0; i < count; ++i) {
      ColmapImage image;
      image.id = in.Read<uint32_t>("image id");
      const std::string where = in.path() + ": image " + std::to_string(image.id);
      double q[4], t[3];
      for (double& v : q) v = in.Read<double>("quaternion");
      for (double& v : t) v = in.Read<double>("translation");
      image.camera_from_world = MakePose(q[0], q[1], q[2], q[3], t[0], t[1], t[2], where);
      image.camera_id = in.Read<uint32_t>("camera id");
      image.name = in.ReadString("image name");
      const uint64_t points = in.Count("2D point count", 24);
      image.points2d.resize(points);
      image.point3d_ids.resize(points);
      for (uint64_t p = 0; p < points; ++p) {
        image.points2d[p].x() = in.Read<double>("2D point x");
        image.points2d[p].y() = in.Read<double>("2D point y");
        if (!image.points2d[p].allFinite()) ThrowError(where, "2D point " + std::to_string(p) + " is not finite");
        const uint64_t id = in.Read<uint64_t>("3D point id");
        image.point3d_ids[p] = id == std::numeric_limits<uint64_t>::max() ? -1 : static_cast<int64_t>(id);
      }
      if (!model.images.emplace(image.id, std::move(image)).second) ThrowError(where, "image id listed twice");
    }
    in.ExpectEnd();
  }
  {
    BinaryReader in(Find(directory, "points3D.bin"));
    const uint64_t count = in.Count("point count", 43);
    for (uint64_t i = 0; i < count; ++i) {
      ColmapPoint3D point;
      point.id = in.Read<uint64_t>("point id");
      for (int c = 0; c < 3; ++c) point.xyz[c] = in.Read<double>("point coordinate");
      for (int c = 0; c < 3; ++c) point.rgb[c] = in.Read<uint8_t>("point colour");
      point.error = in.Read<double>("point error");
      if (!point.xyz.allFinite() || !std::isfinite(point.error)) {
        ThrowError(in.path() + ": point " + std::to_string(point.id), "coordinates or error not finite");
      }
      const uint64_t track = in.Count("track length", 8);
      point.track.resize(track);
      for (auto& element : point.track) {
        element.first = in.Read<uint32_t>("track image id");
        element.second = in.Read<uint32_t>("track point index");
      }
      const uint64_t id = point.id;
      if (!model.points.emplace(id, std::move(point)).second) {
        ThrowError(in.path() + ": point " + std::to_string(id), "point id listed twice");
      }
    }
    in.ExpectEnd();
  }
  model.Validate(directory);
  return model;
}

ColmapModel ColmapModel::ReadText(const std::string& directory) {
  ColmapModel model;
  {
    const std::string path = Find(directory, "cameras.txt");
    for (const auto& [number, line] : DataLines(path)) {
      const std::string where = path + ":" + std::to_string(number);
      const std::vector<std::string> fields = Fields(line);
      if (fields.size() < 4) ThrowError(where, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
      const uint32_t id = static_cast<uint32_t>(ParseUnsigned(fields[0], where, "camera id", UINT32_MAX));
      const std::string& name = fields[1];
      const uint64_t width = ParseUnsigned(fields[2], where, "width", UINT32_MAX);
      const uint64_t height = ParseUnsigned(fields[3], where, "height", UINT32_MAX);
      std::vector<double> params;
      for (size_t f = 4; f < fields.size(); ++f) params.push_back(ParseReal(fields[f], where, "camera parameter"));
      CameraModelId supported;
      if (CameraModelFromName(name, &supported) && static_cast<int>(params.size()) != CameraModelNumParams(supported)) {
        ThrowError(where, "camera model " + name + " has " + std::to_string(CameraModelNumParams(supported)) +
                              " parameters, the line gives " + std::to_string(params.size()));
      }
      if (!model.cameras.emplace(id, MakeCamera(name, width, height, params, where)).second) {
        ThrowError(where, "camera id listed twice");
      }
    }
  }
  {
    const std::string path = Find(directory, "images.txt");
    const auto lines = DataLines(path);
    // Each image has two lines; an image without 2D points has an empty second line, which
    // DataLines drops, so pair lines by content: a pose line has 10 fields, ending in the name.
    for (size_t i = 0; i < lines.size(); ++i) {
      const std::string where = path + ":" + std::to_string(lines[i].first);
      const std::vector<std::string> pose = Fields(lines[i].second);
      if (pose.size() != 10) {
        ThrowError(where, "expected an image line IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME (10 fields), got " +
                              std::to_string(pose.size()) + " fields");
      }
      ColmapImage image;
      image.id = static_cast<uint32_t>(ParseUnsigned(pose[0], where, "image id", UINT32_MAX));
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = ParseReal(pose[1 + k], where, "pose number");
      image.camera_from_world = MakePose(v[0], v[1], v[2], v[3], v[4], v[5], v[6], where);
      image.camera_id = static_cast<uint32_t>(ParseUnsigned(pose[8], where, "camera id", UINT32_MAX));
      image.name = pose[9];
      // The points line, if the next data line is not itself a pose line.
      if (i + 1 < lines.size()) {
        const std::vector<std::string> fields = Fields(lines[i + 1].second);
        const bool is_pose_line = fields.size() == 10;
        if (!is_pose_line) {
          ++i;
          const std::string points_where = path + ":" + std::to_string(lines[i].first);
          if (fields.size() % 3 != 0) ThrowError(points_where, "expected triples X Y POINT3D_ID");
          for (size_t f = 0; f < fields.size(); f += 3) {
            const double x = ParseReal(fields[f], points_where, "2D point x");
            const double y = ParseReal(fields[f + 1], points_where, "2D point y");
            image.points2d.emplace_back(x, y);
            image.point3d_ids.push_back(ParseSigned(fields[f + 2], points_where, "3D point id"));
          }
        }
      }
      const uint32_t id = image.id;
      if (!model.images.emplace(id, std::move(image)).second) ThrowError(where, "image id listed twice");
    }
  }
  {
    const std::string path = Find(directory, "points3D.txt");
    for (const auto& [number, line] : DataLines(path)) {
      const std::string where = path + ":" + std::to_string(number);
      const std::vector<std::string> fields = Fields(line);
      if (fields.size() < 8 || (fields.size() - 8) % 2 != 0) {
        ThrowError(where, "expected POINT3D_ID X Y Z R G B ERROR and (IMAGE_ID POINT2D_IDX) pairs, got " +
                              std::to_string(fields.size()) + " fields");
      }
      ColmapPoint3D point;
      point.id = ParseUnsigned(fields[0], where, "point id", UINT64_MAX);
      for (int c = 0; c < 3; ++c) point.xyz[c] = ParseReal(fields[1 + c], where, "coordinate");
      for (int c = 0; c < 3; ++c)
        point.rgb[c] = static_cast<uint8_t>(ParseUnsigned(fields[4 + c], where, "colour", 255));
      point.error = ParseReal(fields[7], where, "error");
      for (size_t f = 8; f < fields.size(); f += 2) {
        point.track.emplace_back(
            static_cast<uint32_t>(ParseUnsigned(fields[f], where, "track image id", UINT32_MAX)),
            static_cast<uint32_t>(ParseUnsigned(fields[f + 1], where, "track point index", UINT32_MAX)));
      }
      const uint64_t id = point.id;
      if (!model.points.emplace(id, std::move(point)).second) ThrowError(where, "point id listed twice");
    }
  }
  model.Validate(directory);
  return model;
}

void ColmapModel::Validate(const std::string& directory) const {
  for (const auto& [id, image] : images) {
    if (!cameras.count(image.camera_id)) {
      ThrowError(directory,
                 "image " + std::to_string(id) + " refers to missing camera " + std::to_string(image.camera_id));
    }
  }
  for (const auto& [id, point] : points) {
    for (const auto& [image_id, index] : point.track) {
      const auto image = images.find(image_id);
      if (image == images.end() || index >= image->second.points2d.size()) {
        ThrowError(directory, "point " + std::to_string(id) + " has a track element (" + std::to_string(image_id) +
                                  ", " + std::to_string(index) + ") that names no 2D point");
      }
    }
  }
}

void ColmapModel::WriteText(const std::string& directory) const {
  RequireDirectory(directory);
  {
    TextWriter file((fs::path(directory) / "cameras.txt").string());
    std::ofstream& out = file.out();
    out << "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        << "# Number of cameras: " << cameras.size() << "\n";
    for (const auto& [id, camera] : cameras) {
      out << id << " " << CameraModelName(camera.model) << " " << camera.width << " " << camera.height;
      for (double p : camera.params) out << " " << p;
      out << "\n";
    }
    file.Commit();
  }
  {
    TextWriter file((fs::path(directory) / "images.txt").string());
    std::ofstream& out = file.out();
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << "# Number of images: " << images.size() << "\n";
    for (const auto& [id, image] : images) {
      const Eigen::Quaterniond& q = image.camera_from_world.rotation;
      const Eigen::Vector3d& t = image.camera_from_world.translation;
      out << id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x() << " " << t.y() << " "
          << t.z() << " " << image.camera_id << " " << image.name << "\n";
      for (size_t p = 0; p < image.points2d.size(); ++p) {
        out << (p ? " " : "") << image.points2d[p].x() << " " << image.points2d[p].y() << " " << image.point3d_ids[p];
      }
      out << "\n";
    }
    file.Commit();
  }
  {
    TextWriter file((fs::path(directory) / "points3D.txt").string());
    std::ofstream& out = file.out();
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: " << points.size() << "\n";
    for (const auto& [id, point] : points) {
      out << id << " " << point.xyz.x() << " " << point.xyz.y() << " " << point.xyz.z() << " " << int(point.rgb[0])
          << " " << int(point.rgb[1]) << " " << int(point.rgb[2]) << " " << point.error;
      for (const auto& [image_id, index] : point.track) out << " " << image_id << " " << index;
      out << "\n";
    }
    file.Commit();
  }
}

void ColmapModel::WriteBinary(const std::string& directory) const {
  RequireDirectory(directory);
  {
    BinaryWriter out((fs::path(directory) / "cameras.bin").string());
    out.Write<uint64_t>(cameras.size());
    for (const auto& [id, camera] : cameras) {
      out.Write<uint32_t>(id);
      out.Write<int32_t>(ColmapModelIdFromName(CameraModelName(camera.model)));
      out.Write<uint64_t>(static_cast<uint64_t>(camera.width));
      out.Write<uint64_t>(static_cast<uint64_t>(camera.height));
      for (double p : camera.params) out.Write<double>(p);
    }
    out.Commit();
  }
  {
    BinaryWriter out((fs::path(directory) / "images.bin").string());
    out.Write<uint64_t>(images.size());
    for (const auto& [id, image] : images) {
      out.Write<uint32_t>(id);
      const Eigen::Quaterniond& q = image.camera_from_world.rotation;
      for (double v : {q.w(), q.x(), q.y(), q.z()}) out.Write<double>(v);
      for (int k = 0; k < 3; ++k) out.Write<double>(image.camera_from_world.translation[k]);
      out.Write<uint32_t>(image.camera_id);
      out.WriteString(image.name);
      out.Write<uint64_t>(image.points2d.size());
      for (size_t p = 0; p < image.points2d.size(); ++p) {
        out.Write<double>(image.points2d[p].x());
        out.Write<double>(image.points2d[p].y());
        out.Write<uint64_t>(image.point3d_ids[p] < 0 ? std::numeric_limits<uint64_t>::max()
                                                     : static_cast<uint64_t>(image.point3d_ids[p]));
      }
    }
    out.Commit();
  }
  {
    BinaryWriter out((fs::path(directory) / "points3D.bin").string());
    out.Write<uint64_t>(points.size());
    for (const auto& [id, point] : points) {
      out.Write<uint64_t>(id);
      for (int c = 0; c < 3; ++c) out.Write<double>(point.xyz[c]);
      for (int c = 0; c < 3; ++c) out.Write<uint8_t>(point.rgb[c]);
      out.Write<double>(point.error);
      out.Write<uint64_t>(point.track.size());
      for (const auto& [image_id, index] : point.track) {
        out.Write<uint32_t>(image_id);
        out.Write<uint32_t>(index);
      }
    }
    out.Commit();
  }
}

}  // namespace ibrdf
