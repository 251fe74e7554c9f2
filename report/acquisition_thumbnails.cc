#include "report/acquisition_thumbnails.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <tuple>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"
#include "radiometry/linear_image.h"
#include "report/report_png.h"
#include "report/tone_map.h"
#include "scan/ply_io.h"
#include "scan/scan_mesh.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using Polyline = std::vector<Eigen::Vector2d>;

// The mesh in the world frame with its edges, each with the one or two faces beside it, built once for
// every photo's silhouette.
struct MeshEdges {
  std::vector<Eigen::Vector3d> points;    // world frame
  std::vector<Eigen::Vector3d> normals;   // per face, world frame, not normalized
  std::vector<std::array<int, 4>> edges;  // vertex a, vertex b, face, other face (-1: boundary)
};

MeshEdges BuildMeshEdges(const ScanMesh& mesh, const Sim3d& world_from_mesh) {
  MeshEdges out;
  out.points.reserve(mesh.points.size());
  for (const Eigen::Vector3d& p : mesh.points) out.points.push_back(world_from_mesh * p);
  std::vector<std::tuple<int, int, int>> half;  // (low vertex, high vertex, face)
  half.reserve(mesh.faces.size() * 3);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3i& t = mesh.faces[f];
    out.normals.push_back((out.points[t[1]] - out.points[t[0]]).cross(out.points[t[2]] - out.points[t[0]]));
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      half.emplace_back(std::min(a, b), std::max(a, b), int(f));
    }
  }
  std::sort(half.begin(), half.end());
  for (size_t i = 0; i < half.size();) {
    size_t j = i + 1;
    while (j < half.size() && std::get<0>(half[j]) == std::get<0>(half[i]) &&
           std::get<1>(half[j]) == std::get<1>(half[i])) {
      ++j;
    }
    // A non-manifold edge (three or more faces) is drawn from its first two faces.
    out.edges.push_back(
        {std::get<0>(half[i]), std::get<1>(half[i]), std::get<2>(half[i]), j > i + 1 ? std::get<2>(half[i + 1]) : -1});
    i = j;
  }
  return out;
}

// Two unit vectors completing `u` (unit) to an orthonormal frame.
void Complete(const Eigen::Vector3d& u, Eigen::Vector3d* v, Eigen::Vector3d* w) {
  const Eigen::Vector3d seed = std::abs(u.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  *v = u.cross(seed).normalized();
  *w = u.cross(*v);
}

// Projects world points into pixels, splitting the line where a point lies behind the camera.
class Projector {
 public:
  Projector(const Camera& camera, const Rigid3d& camera_from_world, std::vector<Polyline>* out)
      : camera_(camera), camera_from_world_(camera_from_world), out_(out) {}

  void Line(const std::vector<Eigen::Vector3d>& points_in_world) {
    Polyline line;
    for (const Eigen::Vector3d& p : points_in_world) {
      const Eigen::Vector3d p_in_camera = camera_from_world_ * p;
      if (p_in_camera.z() <= 1e-9) {
        Flush(&line);
        continue;
      }
      line.push_back(camera_.ImageFromCamera(p_in_camera));
    }
    Flush(&line);
  }

  // A circle of centre `c` and radius `r` in the plane spanned by `v` and `w` (orthonormal), closed.
  void Circle(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& v, const Eigen::Vector3d& w, int n) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i <= n; ++i) {
      const double t = 2.0 * kPi * i / n;
      points.push_back(c + r * (std::cos(t) * v + std::sin(t) * w));
    }
    Line(points);
  }

 private:
  void Flush(Polyline* line) {
    if (line->size() >= 2) out_->push_back(*line);
    line->clear();
  }

  const Camera& camera_;
  const Rigid3d& camera_from_world_;
  std::vector<Polyline>* out_;
};

std::vector<Polyline> Outline(const Session& session, const Rigid3d& camera_from_world, const MeshEdges* mesh, int n) {
  std::vector<Polyline> out;
  Projector project(session.camera, camera_from_world, &out);
  const Eigen::Vector3d eye = camera_from_world.Inverse().translation;  // the camera centre, world frame
  const SampleSpec& sample = session.sample;
  switch (sample.kind) {
    case SampleSpec::Kind::kSphere: {
      const Eigen::Vector3d to_eye = eye - sample.center;
      const double d = to_eye.norm(), r = sample.radius;
      if (!(d > r)) break;
      const Eigen::Vector3d u = to_eye / d;
      Eigen::Vector3d v, w;
      Complete(u, &v, &w);
      project.Circle(sample.center + (r * r / d) * u, r * std::sqrt(1.0 - (r * r) / (d * d)), v, w, n);
      break;
    }
    case SampleSpec::Kind::kCylinder: {
      const Eigen::Vector3d a = sample.axis.normalized();
      const Eigen::Vector3d to_eye = eye - sample.center;
      const Eigen::Vector3d across = to_eye - to_eye.dot(a) * a;
      const double d = across.norm(), r = sample.radius, half = 0.5 * sample.length;
      Eigen::Vector3d u, v;
      if (d > 1e-12) {
        u = across / d;
        v = a.cross(u);
      } else {
        Complete(a, &u, &v);
      }
      for (const double end : {-half, half}) project.Circle(sample.center + end * a, r, u, v, n);
      if (d > r) {
        const double alpha = std::acos(r / d);
        for (const double sign : {-1.0, 1.0}) {
          const Eigen::Vector3d normal = std::cos(alpha) * u + sign * std::sin(alpha) * v;
          std::vector<Eigen::Vector3d> points;
          // Several points along the line: distortion bends its image.
          const int steps = std::max(2, n / 8);
          for (int i = 0; i <= steps; ++i)
            points.push_back(sample.center + r * normal + (-half + 2.0 * half * i / steps) * a);
          project.Line(points);
        }
      }
      break;
    }
    case SampleSpec::Kind::kMesh: {
      if (!mesh) break;
      for (const std::array<int, 4>& e : mesh->edges) {
        // Boundary edges are left out: on a scan mesh they are mostly the seams between merged scans,
        // drawn across the object's face. Both faces are judged from the edge's own vertex.
        if (e[3] < 0) continue;
        const Eigen::Vector3d to_eye = eye - mesh->points[e[0]];
        const bool silhouette = (mesh->normals[e[2]].dot(to_eye) > 0.0) != (mesh->normals[e[3]].dot(to_eye) > 0.0);
        if (silhouette) project.Line({mesh->points[e[0]], mesh->points[e[1]]});
      }
      break;
    }
  }
  return out;
}

// Sets the pixels the segments of `line` (thumbnail coordinates) cross to green.
void Draw(const Polyline& line, Image* image) {
  auto set = [image](const Eigen::Vector2d& q) {
    const int x = int(std::floor(q.x())), y = int(std::floor(q.y()));
    if (x < 0 || y < 0 || x >= image->width || y >= image->height) return;
    image->at(x, y, 0) = 0.0f;
    image->at(x, y, 1) = 1.0f;
    image->at(x, y, 2) = 0.0f;
  };
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector2d a = line[i], b = line[i + 1];
    const int steps = std::min(4096, int(std::ceil(2.0 * (b - a).lpNorm<Eigen::Infinity>())) + 1);
    for (int k = 0; k <= steps; ++k) set(a + (b - a) * (double(k) / steps));
  }
}

}  // namespace

bool AcquisitionThumbnailOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(max_photos, 1, 1000);
  IBRDF_CHECK_OPTION_RANGE(size_px, 16, 1024);
  IBRDF_CHECK_OPTION_RANGE(outline_points, 8, 100000);
  return true;
}

std::vector<std::vector<Eigen::Vector2d>> SampleOutline(const Session& session, const Rigid3d& camera_from_world,
                                                        const ScanMesh* mesh, int outline_points) {
  if (session.sample.kind == SampleSpec::Kind::kMesh && mesh) {
    const MeshEdges edges = BuildMeshEdges(*mesh, session.sample.world_from_mesh);
    return Outline(session, camera_from_world, &edges, outline_points);
  }
  return Outline(session, camera_from_world, nullptr, outline_points);
}

Image ShrinkRegion(const Image& photo, const PixelBox& box, int size, int* step_out) {
  const int w = box.width(), h = box.height();
  const int step = std::max(1, static_cast<int>(std::ceil(double(std::max(w, h)) / size)));
  Image small(std::max(1, w / step), std::max(1, h / step), 3);
  for (int y = 0; y < small.height; ++y) {
    for (int x = 0; x < small.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (int dy = 0; dy < step; ++dy) {
          for (int dx = 0; dx < step; ++dx) {
            sum += photo.at(box.x0 + x * step + dx, box.y0 + y * step + dy, std::min(c, photo.channels - 1));
          }
        }
        small.at(x, y, c) = static_cast<float>(sum / (step * step));
      }
    }
  }
  if (step_out) *step_out = step;
  return small;
}

nlohmann::json WriteAcquisitionThumbnails(const Session& session, const std::map<uint32_t, PhotoStats>& photos,
                                          const std::string& tmp_dir, const AcquisitionThumbnailOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("acquisition thumbnail options", why);
  std::vector<size_t> measurement;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    if (session.photos[i].role == PhotoRole::kMeasurement) measurement.push_back(i);
  }
  std::vector<size_t> chosen;
  const size_t n = measurement.size(), m = std::min<size_t>(n, size_t(options.max_photos));
  for (size_t k = 0; k < m; ++k) {
    // The first and the last photo and evenly between (all of them when there are few enough).
    const size_t i = m == 1 ? 0 : size_t(std::llround(double(k) * double(n - 1) / double(m - 1)));
    if (chosen.empty() || chosen.back() != measurement[i]) chosen.push_back(measurement[i]);
  }
  nlohmann::json result = {{"measurement_photos", n}, {"size_px", options.size_px}};
  std::optional<MeshEdges> mesh;
  if (session.sample.kind == SampleSpec::Kind::kMesh) {
    try {
      mesh = BuildMeshEdges(ReadPly(session.AbsolutePath(session.sample.mesh_file)), session.sample.world_from_mesh);
    } catch (const Error& e) {
      result["note"] = std::string("no mesh outline: ") + e.what();
    }
  }
  fs::create_directories(fs::path(tmp_dir) / "acquisition");
  nlohmann::json entries = nlohmann::json::array();
  // The thumbnails, linear until every one is read (they share a tone scale).
  struct Pending {
    Image linear;
    double scale = 0.0;
    std::vector<Polyline> outline;  // thumbnail coordinates
    std::string file;
    size_t entry = 0;  // in `entries`
  };
  std::vector<Pending> pending;
  for (const size_t index : chosen) {
    const auto stats = photos.find(uint32_t(index));
    nlohmann::json entry = {{"index", index}, {"samples", stats == photos.end() ? 0 : stats->second.count}};
    try {
      Image photo = ReadImage(session.PhotoPath(index));
      LinearizeImage(session, index, &photo, /*divide_by_exposure=*/true);
      const std::optional<Rigid3d>& pose = session.photos[index].camera_from_world;
      const std::vector<Polyline> outline =
          pose ? Outline(session, *pose, mesh ? &*mesh : nullptr, options.outline_points) : std::vector<Polyline>();
      // The box: the outline's (inside the photo) and the samples', with a margin; the whole photo
      // when neither is in it.
      double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
      for (const Polyline& line : outline) {
        for (const Eigen::Vector2d& p : line) {
          x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y()), x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
        }
      }
      if (stats != photos.end() && stats->second.count > 0) {
        x0 = std::min(x0, double(stats->second.x0)), y0 = std::min(y0, double(stats->second.y0));
        x1 = std::max(x1, double(stats->second.x1 + 1)), y1 = std::max(y1, double(stats->second.y1 + 1));
      }
      x0 = std::max(x0, 0.0), y0 = std::max(y0, 0.0);
      x1 = std::min(x1, double(photo.width)), y1 = std::min(y1, double(photo.height));
      PixelBox box{0, 0, photo.width - 1, photo.height - 1};
      if (x1 > x0 && y1 > y0) {
        const int pad = std::max(4, int(std::max(x1 - x0, y1 - y0) / 8));
        box = {std::max(0, int(std::floor(x0)) - pad), std::max(0, int(std::floor(y0)) - pad),
               std::min(photo.width - 1, int(std::ceil(x1)) + pad),
               std::min(photo.height - 1, int(std::ceil(y1)) + pad)};
      }
      Pending thumbnail;
      int step = 1;
      thumbnail.linear = ShrinkRegion(photo, box, options.size_px, &step);
      ToneMap(thumbnail.linear, &thumbnail.scale);
      for (const Polyline& line : outline) {
        Polyline local;
        for (const Eigen::Vector2d& p : line) local.push_back((p - Eigen::Vector2d(box.x0, box.y0)) / step);
        thumbnail.outline.push_back(local);
      }
      char name[40];
      std::snprintf(name, sizeof(name), "acquisition/%03zu.png", index);
      thumbnail.file = name;
      thumbnail.entry = entries.size();
      pending.push_back(std::move(thumbnail));
      entry["file"] = name;
      entry["outline"] = !outline.empty();
      entry["crop"] = {box.x0, box.y0, box.x1, box.y1};
      entry["step"] = step;
    } catch (const Error& e) {
      entry["note"] = e.what();
    }
    entries.push_back(entry);
  }
  // One tone scale for all (the median of their own): a photo darker than the others reads darker
  // (a view against the light is dark, not its noise stretched to white).
  std::vector<double> scales;
  for (const Pending& thumbnail : pending) {
    if (std::isfinite(thumbnail.scale) && thumbnail.scale > 0.0) scales.push_back(thumbnail.scale);
  }
  const double scale = scales.empty() ? 1.0 : Median(scales);
  for (const Pending& thumbnail : pending) {
    Image image = ToneMapWithScale(thumbnail.linear, scale);
    for (const Polyline& line : thumbnail.outline) Draw(line, &image);
    try {
      WriteReportPng((fs::path(tmp_dir) / thumbnail.file).string(), image);
    } catch (const Error& e) {
      entries[thumbnail.entry].erase("file");
      entries[thumbnail.entry]["note"] = e.what();
    }
  }
  result["shown"] = entries.size();
  result["photos"] = entries;
  Log(2, "report: " + std::to_string(entries.size()) + " of " + std::to_string(n) +
             " measurement photos as thumbnails with the sample's outline");
  return result;
}

}  // namespace ibrdf
