#include "align/colmap_model.h"

#include <cmath>
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

template <typename T>
T Parse(std::istringstream& in, const std::string& where, const char* what) {
  T value;
  if (!(in >> value)) ThrowError(where, std::string("expected ") + what);
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
      for (double& p : params) p = in.Read<double>("camera parameter");
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
      std::istringstream in(line);
      const uint32_t id = Parse<uint32_t>(in, where, "a camera id");
      const std::string name = Parse<std::string>(in, where, "a camera model");
      const uint64_t width = Parse<uint64_t>(in, where, "a width");
      const uint64_t height = Parse<uint64_t>(in, where, "a height");
      std::vector<double> params;
      double p;
      while (in >> p) params.push_back(p);
      if (!in.eof()) ThrowError(where, "expected numeric camera parameters");
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
      std::istringstream in(lines[i].second);
      ColmapImage image;
      image.id = Parse<uint32_t>(in, where, "an image id");
      double v[7];
      for (double& x : v) x = Parse<double>(in, where, "a pose number");
      image.camera_from_world = MakePose(v[0], v[1], v[2], v[3], v[4], v[5], v[6], where);
      image.camera_id = Parse<uint32_t>(in, where, "a camera id");
      image.name = Parse<std::string>(in, where, "an image name");
      // The points line, if the next data line is not itself a pose line.
      if (i + 1 < lines.size()) {
        std::istringstream points(lines[i + 1].second);
        std::vector<std::string> fields;
        std::string field;
        while (points >> field) fields.push_back(field);
        const bool is_pose_line = fields.size() == 10;
        if (!is_pose_line) {
          ++i;
          if (fields.size() % 3 != 0) {
            ThrowError(path + ":" + std::to_string(lines[i].first), "expected triples X Y POINT3D_ID");
          }
          for (size_t f = 0; f < fields.size(); f += 3) {
            image.points2d.emplace_back(std::stod(fields[f]), std::stod(fields[f + 1]));
            image.point3d_ids.push_back(std::stoll(fields[f + 2]));
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
      std::istringstream in(line);
      ColmapPoint3D point;
      point.id = Parse<uint64_t>(in, where, "a point id");
      for (int c = 0; c < 3; ++c) point.xyz[c] = Parse<double>(in, where, "a coordinate");
      for (int c = 0; c < 3; ++c) {
        const int value = Parse<int>(in, where, "a colour");
        if (value < 0 || value > 255) ThrowError(where, "colour out of range");
        point.rgb[c] = static_cast<uint8_t>(value);
      }
      point.error = Parse<double>(in, where, "an error");
      uint32_t image_id, point_index;
      while (in >> image_id >> point_index) point.track.emplace_back(image_id, point_index);
      if (!in.eof()) ThrowError(where, "expected track pairs IMAGE_ID POINT2D_IDX");
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
