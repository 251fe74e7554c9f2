#include "derender/synthetic.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "align/markers.h"
#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/logging.h"
#include "core/radiometry.h"
#include "core/statistics.h"
#include "derender/analytic_sample.h"
#include "derender/synthetic_radiometry.h"
#include "derender/synthetic_targets.h"
#include "scan/ply_io.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {
constexpr double kDegree = M_PI / 180.0;

// Where an irregular-shape session keeps its scan (relative to the session folder).
constexpr char kScanMesh[] = "scan/mesh.ply";
constexpr char kTruthMesh[] = "truth-mesh.ply";

// The true shape a session renders: the irregular shape, or the session's own sphere or cylinder.
std::unique_ptr<AnalyticSample> TrueSample(const SynthOptions& options, const Session& session) {
  if (options.shape != SynthOptions::Shape::kNone) return MakeTrueShape(options);
  return AnalyticSample::Create(session.sample);
}

// The session (camera, light, sample, poses) an options object describes, without photos on disk.
Session BuildSession(const SynthOptions& options) {
  Session session;
  SampleSpec& sample = session.sample;
  double bounding_radius = 0.0;
  if (options.shape != SynthOptions::Shape::kNone) {
    sample.kind = SampleSpec::Kind::kMesh;
    sample.mesh_file = kScanMesh;
    bounding_radius = MakeTrueShape(options)->BoundingRadius();
  } else {
    sample.kind = options.sample;
    sample.center = options.origin;
    sample.radius = options.sample_radius;
    if (sample.kind == SampleSpec::Kind::kCylinder) {
      sample.axis = Eigen::Vector3d::UnitZ();
      sample.length = options.cylinder_length;
    }
    bounding_radius = AnalyticSample::Create(sample)->BoundingRadius();
  }

  session.light.kind = Light::Kind::kPoint;
  session.light.position = options.origin + options.light_distance * Eigen::Vector3d::UnitX();
  session.light.intensity = options.light_intensity;

  const double framed_radius = options.targets ? std::max(bounding_radius, options.platform_radius) : bounding_radius;
  const double half_angle = std::asin(std::min(1.0, framed_radius / options.camera_distance));
  const double focal = options.frame_fraction * 0.5 * std::min(options.width, options.height) / std::tan(half_angle);
  session.camera = Camera::Create(
      CameraModelId::kOpenCV, options.width, options.height,
      {focal, focal, 0.5 * options.width, 0.5 * options.height, options.k1, options.k2, options.p1, options.p2},
      "synth camera");

  const CameraEffects& effects = options.effects;
  session.radiometry.response.kind = effects.srgb ? Response::Kind::kSrgb : Response::Kind::kLinear;
  session.radiometry.black_level = effects.black_level;
  // Unclipped float files have no saturation level; the largest float stands for "none".
  session.radiometry.saturation_level = effects.clip ? 1.0 : double(std::numeric_limits<float>::max());
  if (effects.shot_noise || effects.read_noise || effects.bits > 0) {
    CameraNoise noise;
    noise.full_well_e = effects.full_well_e;
    noise.read_noise_e = effects.read_noise ? effects.read_noise_e : 0.0;
    noise.bits = effects.bits;
    if (!effects.shot_noise) noise.full_well_e = 1e30;  // no shot noise: an infinitely deep well
    session.radiometry.noise = noise;
  }

  if (options.targets) {
    TargetsSpec targets;
    targets.dictionary = options.target_dictionary;
    targets.reference = TargetLayout(options);
    const SampleTargetsSpec sample_targets = SampleTargetLayout(options, nullptr);
    if (!sample_targets.markers.empty()) targets.sample = sample_targets;
    const LightTargetsSpec light = LightTargetLayout(options, nullptr);
    if (!light.markers.empty()) targets.light = light;
    session.targets = targets;
  }

  const double elevation = options.camera_elevation_deg * kDegree;
  for (int i = 0; i < options.num_photos; ++i) {
    const double t = options.num_photos == 1 ? 0.0 : double(i) / (options.num_photos - 1);
    const double azimuth = (options.arc_start_deg + t * (options.arc_end_deg - options.arc_start_deg)) * kDegree;
    const Eigen::Vector3d direction(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                    std::sin(elevation));
    PhotoSpec photo;
    char name[32];
    std::snprintf(name, sizeof(name), "photos/%03d.%s", i, effects.bits == 0 ? "exr" : "png");
    photo.file = name;
    photo.camera_from_world = LookAtCameraFromWorld(options.origin + options.camera_distance * direction,
                                                    options.origin, Eigen::Vector3d::UnitZ());
    session.photos.push_back(photo);
  }
  // Target photos: from behind and above the sample, opposite the light, looking past the sample at
  // the light's card, turned so the long side of the frame runs from the platform to the card; spread
  // sideways (0.25 m apart) so the card's markers are seen from several directions.
  if (options.targets && options.light_target_photos > 0) {
    const int n = options.light_target_photos;
    for (int k = 0; k < n; ++k) {
      const double lateral = 0.25 * (k - 0.5 * (n - 1));
      PhotoSpec photo;
      char name[40];
      std::snprintf(name, sizeof(name), "photos/target-%03d.%s", k, effects.bits == 0 ? "exr" : "png");
      photo.file = name;
      photo.role = PhotoRole::kTargets;
      // A roll of 10 to 18 degrees keeps the markers' sides off the pixel grid: an edge along a pixel
      // row is anti-aliased by CompositeTargets' 4 x 4 rays in quarter-pixel steps (a corner bias of up
      // to 0.12 px, which the light's 2 m lever turns into millimetres).
      const Rigid3d roll(Eigen::Quaterniond(Eigen::AngleAxisd((10.0 + 4.0 * k) * kDegree, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d::Zero());
      photo.camera_from_world =
          roll * LookAtCameraFromWorld(options.origin + Eigen::Vector3d(-0.7, lateral, 0.55),
                                       options.origin + Eigen::Vector3d(0.35, -0.2 * lateral, -0.1),
                                       -Eigen::Vector3d::UnitY());
      session.photos.push_back(photo);
    }
  }
  ExpandBrackets(options, &session);  // radiometry hook: exposure brackets
  return session;
}

// The platform plane's height: the sample rests on it.
double PlatformHeight(const SynthOptions& options) {
  if (options.shape != SynthOptions::Shape::kNone) return options.origin.z() + MakeTrueShape(options)->LowestZ();
  const double below =
      options.sample == SampleSpec::Kind::kCylinder ? 0.5 * options.cylinder_length : options.sample_radius;
  return options.origin.z() - below;
}

// A flat board carrying markers on white cards: the platform (a dark disk) or the light's card (a
// white rectangle).
struct Board {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX(), v_axis = Eigen::Vector3d::UnitY();  // in-plane, unit
  double radius = 0.0;  // a disk of this radius when > 0, else a rectangle
  double half_u = 0.0, half_v = 0.0;
  double background = 0.0;  // the board's value off the marker cards
  std::vector<TargetSpec> markers;
  std::vector<std::vector<bool>> modules;
};

// The boards of a target session, and their appearance along a ray.
class TargetScene {
 public:
  explicit TargetScene(const SynthOptions& options)
      : options_(options), dictionary_(options.target_dictionary, "synth --target-dictionary") {
    Board platform;
    platform.center = Eigen::Vector3d(options.origin.x(), options.origin.y(), PlatformHeight(options));
    platform.radius = options.platform_radius;
    platform.background = options.target_black;
    platform.markers = TargetLayout(options);
    boards_.push_back(platform);
    std::vector<TargetSpec> light_markers;
    LightTargetLayout(options, &light_markers);
    if (!light_markers.empty()) {
      // The card: the markers' cards side by side, in the plane through the light facing the sample.
      Board card;
      const Eigen::Vector3d light = options.origin + options.light_distance * Eigen::Vector3d::UnitX();
      card.center = light - options.light_card_drop * Eigen::Vector3d::UnitZ();
      card.normal = Eigen::Vector3d::UnitX();
      card.u_axis = Eigen::Vector3d::UnitY();
      card.v_axis = Eigen::Vector3d::UnitZ();
      const double pitch = options.light_marker_size * (1.0 + 2.0 * options.card_margin);
      card.half_u = 0.5 * pitch * options.light_marker_count;
      card.half_v = 0.5 * pitch;
      card.background = options.target_white;
      card.markers = light_markers;
      boards_.push_back(card);
    }
    std::vector<TargetSpec> sample_markers;
    SampleTargetLayout(options, &sample_markers);
    if (!sample_markers.empty()) {
      // The cylinder's top cap: a black disk carrying the sample's markers.
      Board cap;
      cap.center = options.origin + 0.5 * options.cylinder_length * Eigen::Vector3d::UnitZ();
      cap.radius = options.sample_radius;
      cap.background = options.target_black;
      cap.markers = sample_markers;
      boards_.push_back(cap);
    }
    for (Board& board : boards_) {
      for (const TargetSpec& target : board.markers) board.modules.push_back(dictionary_.Modules(target.id));
    }
  }

  // The value of the nearest board along the ray, its distance in `t`; < 0 where no board is hit.
  double Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* t) const {
    double best = -1.0;
    *t = std::numeric_limits<double>::infinity();
    for (const Board& board : boards_) {
      const double denominator = direction.dot(board.normal);
      if (!(std::abs(denominator) > 1e-12)) continue;
      const double tb = (board.center - origin).dot(board.normal) / denominator;
      if (!(tb > 0.0) || !(tb < *t)) continue;
      const double value = At(board, origin + tb * direction);
      if (value < 0.0) continue;
      best = value;
      *t = tb;
    }
    return best;
  }

 private:
  // The value in [black, white] at a point on the board's plane; < 0 off the board.
  double At(const Board& board, const Eigen::Vector3d& p) const {
    const Eigen::Vector3d offset = p - board.center;
    if (board.radius > 0.0) {
      if ((offset - offset.dot(board.normal) * board.normal).norm() > board.radius) return -1.0;
    } else if (std::abs(offset.dot(board.u_axis)) > board.half_u || std::abs(offset.dot(board.v_axis)) > board.half_v) {
      return -1.0;
    }
    const int n = dictionary_.modules();
    for (size_t m = 0; m < board.markers.size(); ++m) {
      // Marker axes from its corners: x along top-left -> top-right, y along top-left -> bottom-left.
      const std::array<Eigen::Vector3d, 4>& c = board.markers[m].corners;
      const Eigen::Vector3d x_axis = c[1] - c[0], y_axis = c[3] - c[0];
      const double u = (p - c[0]).dot(x_axis) / x_axis.squaredNorm();
      const double v = (p - c[0]).dot(y_axis) / y_axis.squaredNorm();
      const double margin = options_.card_margin;
      if (u < -margin || u >= 1.0 + margin || v < -margin || v >= 1.0 + margin) continue;
      if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) return options_.target_white;  // the card's border
      const int col = std::min(n - 1, int(u * n)), row = std::min(n - 1, int(v * n));
      return board.modules[m][size_t(row) * n + col] ? options_.target_white : options_.target_black;
    }
    return board.background;
  }

  const SynthOptions& options_;
  MarkerDictionary dictionary_;
  std::vector<Board> boards_;
};

// Composites the target boards into a photo's linear signal where the pixel centre misses the sample:
// 4 x 4 rays per pixel, the boards' fraction of them averaged (sharp, anti-aliased marker edges).
void CompositeTargets(const Session& session, size_t photo_index, const TargetScene& scene,
                      const AnalyticSample& sample, const std::vector<uint8_t>& sample_mask, Image* signal) {
  const Camera& camera = session.camera;
  const Rigid3d world_from_camera = session.photos[photo_index].camera_from_world->Inverse();
  const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d center = world_from_camera.translation;
  // The boards' value along a ray through an image point; 0 where it shows nothing (or the sample
  // is in front).
  auto value_at = [&](const Eigen::Vector2d& pixel) {
    const Eigen::Vector2d xy = camera.CamPlaneFromImage(pixel);
    const Eigen::Vector3d direction = (rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
    double t;
    const double value = scene.Trace(center, direction, &t);
    if (!(value > 0.0)) return 0.0;
    SurfaceHit hit;
    if (sample.Intersect(center, direction, &hit) && hit.t < t) return 0.0;
    return value;
  };
  // Values at the pixel corners; a pixel whose four corners agree is uniform (one value), the others
  // (edges) are averaged over 4 x 4 rays.
  const int w = camera.width, h = camera.height;
  std::vector<double> corners(size_t(w + 1) * (h + 1));
  tbb::parallel_for(0, h + 1, [&](int y) {
    for (int x = 0; x <= w; ++x) corners[size_t(y) * (w + 1) + x] = value_at(Eigen::Vector2d(x, y));
  });
  constexpr int kRays = 4;
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      if (sample_mask[size_t(y) * w + x]) continue;
      const double c00 = corners[size_t(y) * (w + 1) + x], c10 = corners[size_t(y) * (w + 1) + x + 1];
      const double c01 = corners[size_t(y + 1) * (w + 1) + x], c11 = corners[size_t(y + 1) * (w + 1) + x + 1];
      double value = c00;
      if (c00 != c10 || c00 != c01 || c00 != c11) {
        double sum = 0.0;
        for (int sy = 0; sy < kRays; ++sy) {
          for (int sx = 0; sx < kRays; ++sx) {
            sum += value_at(Eigen::Vector2d(x + (sx + 0.5) / kRays, y + (sy + 0.5) / kRays));
          }
        }
        value = sum / (kRays * kRays);
      }
      if (value > 0.0) {
        for (int c = 0; c < 3; ++c) signal->at(x, y, c) += static_cast<float>(value);
      }
    }
  });
}

// The fine truth mesh: a latitude-longitude grid of directions from the centre, each mapped to the
// surface point along it (every shape is star-shaped about its centre), with the exact normals.
ScanMesh TruthMesh(const ImplicitSample& shape, double spacing_m) {
  const int rings = std::max(8, static_cast<int>(std::ceil(M_PI * shape.BoundingRadius() / spacing_m)));
  const int segments = 2 * rings;
  ScanMesh mesh;
  mesh.points.resize(size_t(rings - 1) * segments + 2);
  mesh.normals.resize(mesh.points.size());
  auto solve = [&](size_t index, double theta, double phi) {
    const Eigen::Vector3d u(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    mesh.points[index] = shape.RadialPoint(u, &mesh.normals[index]);
  };
  solve(0, 0.0, 0.0);
  solve(mesh.points.size() - 1, M_PI, 0.0);
  tbb::parallel_for(1, rings, [&](int i) {
    for (int j = 0; j < segments; ++j) {
      solve(1 + size_t(i - 1) * segments + j, M_PI * i / rings, 2.0 * M_PI * j / segments);
    }
  });
  const int south = static_cast<int>(mesh.points.size()) - 1;
  auto at = [&](int ring, int segment) { return 1 + (ring - 1) * segments + (segment % segments); };
  for (int j = 0; j < segments; ++j) {
    mesh.faces.emplace_back(0, at(1, j), at(1, j + 1));
    mesh.faces.emplace_back(south, at(rings - 1, j + 1), at(rings - 1, j));
  }
  for (int i = 1; i + 1 < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      mesh.faces.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      mesh.faces.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return mesh;
}

nlohmann::json RigidJson(const Rigid3d& transform) {
  const Eigen::Quaterniond& q = transform.rotation;
  return {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", ToJson(transform.translation)}};
}

Image RenderRadianceImpl(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                         const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask,
                         uint64_t* shadowed_pixels, const Eigen::Vector3d& fill_irradiance);

}  // namespace

const char* SynthShapeName(SynthOptions::Shape shape) {
  switch (shape) {
    case SynthOptions::Shape::kNone:
      return "none";
    case SynthOptions::Shape::kSquash:
      return "squash";
    case SynthOptions::Shape::kPot:
      return "pot";
    case SynthOptions::Shape::kDent:
      return "dent";
  }
  return "none";
}

SynthOptions::Shape SynthShapeFromName(const std::string& name) {
  for (SynthOptions::Shape shape : {SynthOptions::Shape::kNone, SynthOptions::Shape::kSquash, SynthOptions::Shape::kPot,
                                    SynthOptions::Shape::kDent}) {
    if (name == SynthShapeName(shape)) return shape;
  }
  ThrowError("synth shape", "unknown shape \"" + name + "\" (expected squash, pot or dent)");
}

std::unique_ptr<ImplicitSample> MakeTrueShape(const SynthOptions& options) {
  switch (options.shape) {
    case SynthOptions::Shape::kNone:
      return nullptr;
    case SynthOptions::Shape::kSquash:
      return std::make_unique<SquashSample>(options.origin, options.squash);
    case SynthOptions::Shape::kPot:
      return std::make_unique<PotSample>(options.origin, options.pot);
    case SynthOptions::Shape::kDent:
      return std::make_unique<DentedSphereSample>(options.origin, options.dent);
  }
  return nullptr;
}

Rigid3d ScanFromWorld(const SynthOptions& options) {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(35.0 * kDegree, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  return Rigid3d(rotation, options.scan_offset_m * Eigen::Vector3d(0.6, -0.48, 0.64));
}

std::vector<TargetSpec> TargetLayout(const SynthOptions& options) {
  std::vector<TargetSpec> layout;
  if (!options.targets) return layout;
  const double z = PlatformHeight(options);
  const double half = 0.5 * options.target_size;
  // Printed upright for a viewer above: x east, y south, so x cross y points down into the platform.
  const Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX(), y_axis = -Eigen::Vector3d::UnitY();
  for (int k = 0; k < options.target_count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.5) / options.target_count;
    const Eigen::Vector3d center = Eigen::Vector3d(options.origin.x(), options.origin.y(), z) +
                                   options.target_ring_radius * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    TargetSpec target;
    target.id = k;
    target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                      center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
    layout.push_back(target);
  }
  return layout;
}

LightTargetsSpec LightTargetLayout(const SynthOptions& options, std::vector<TargetSpec>* corners) {
  LightTargetsSpec spec;
  if (corners) corners->clear();
  if (!options.targets || options.light_target_photos <= 0) return spec;
  spec.size = options.light_marker_size;
  const Eigen::Vector3d light = options.origin + options.light_distance * Eigen::Vector3d::UnitX();
  // Printed upright for a viewer at the sample looking at the light: x along -y, y down (-z), so
  // x cross y (into the print) points away from the sample, along +x.
  const Eigen::Vector3d x_axis = -Eigen::Vector3d::UnitY(), y_axis = -Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d world_from_marker;
  world_from_marker << x_axis, y_axis, x_axis.cross(y_axis);
  const double pitch = options.light_marker_size * (1.0 + 2.0 * options.card_margin);
  const double half = 0.5 * options.light_marker_size;
  for (int k = 0; k < options.light_marker_count; ++k) {
    const Eigen::Vector3d center = light - options.light_card_drop * Eigen::Vector3d::UnitZ() +
                                   pitch * (k - 0.5 * (options.light_marker_count - 1)) * x_axis;
    LightMarkerSpec marker;
    marker.id = options.light_marker_first_id + k;
    marker.light_in_marker = world_from_marker.transpose() * (light - center);
    spec.markers.push_back(marker);
    if (corners) {
      TargetSpec target;
      target.id = marker.id;
      target.corners = {center - half * x_axis - half * y_axis, center + half * x_axis - half * y_axis,
                        center + half * x_axis + half * y_axis, center - half * x_axis + half * y_axis};
      corners->push_back(target);
    }
  }
  return spec;
}

CameraEffects CameraEffects::None() {
  CameraEffects effects;
  effects.shot_noise = false;
  effects.read_noise = false;
  effects.bits = 0;
  effects.srgb = false;
  effects.black_level = 0.0;
  effects.supersample = 1;
  return effects;
}

bool CameraEffects::Check(std::string* why) const {
  if (bits != 0 && (bits < 8 || bits > 16)) {
    *why = "bits must be 0 (float) or 8 to 16";
    return false;
  }
  if (!(full_well_e > 0.0) || !(read_noise_e >= 0.0)) {
    *why = "full_well_e must be positive and read_noise_e non-negative";
    return false;
  }
  if (!(black_level >= 0.0 && black_level < 0.5)) {
    *why = "black_level must be in [0, 0.5)";
    return false;
  }
  if (supersample < 1 || supersample > 16) {
    *why = "supersample must be 1 to 16";
    return false;
  }
  if (!(vignetting >= 0.0 && vignetting < 0.9)) {
    *why = "vignetting must be in [0, 0.9)";
    return false;
  }
  return true;
}

bool SynthOptions::Check(std::string* why) const {
  if (sample == SampleSpec::Kind::kMesh) {
    *why = "synth renders a sphere or a cylinder (or, with shape, a squash, pot or dent as a mesh sample)";
    return false;
  }
  if (!(sample_radius > 0.0) || !(cylinder_length > 0.0)) {
    *why = "sample sizes must be positive";
    return false;
  }
  double bounding =
      sample == SampleSpec::Kind::kCylinder ? std::hypot(sample_radius, 0.5 * cylinder_length) : sample_radius;
  if (shape != Shape::kNone) {
    if (!squash.Check(why) || !pot.Check(why) || !dent.Check(why) || !scanner.Check(why)) return false;
    if (!targets) {
      *why = "an irregular shape needs targets: the platform's markers register its scan to the photos";
      return false;
    }
    if (!(scan_offset_m >= 0.0) || !(scan_target_noise_m >= 0.0) || !(truth_mesh_spacing_m > 0.0)) {
      *why = "scan_offset_m and scan_target_noise_m must be >= 0, truth_mesh_spacing_m > 0";
      return false;
    }
    bounding = MakeTrueShape(*this)->BoundingRadius();
    if (!(scanner.distance_m > 1.5 * bounding)) {
      *why = "the scanner must be well outside the sample";
      return false;
    }
    if (!(truth_mesh_spacing_m < 0.1 * bounding)) {
      *why = "truth_mesh_spacing_m must be below a tenth of the sample's size";
      return false;
    }
  }
  if (!(camera_distance > 1.5 * bounding) || !(light_distance > bounding)) {
    *why = "the camera and the light must be well outside the sample";
    return false;
  }
  if (num_photos < 1 || num_photos > 100000) {
    *why = "num_photos must be 1 to 100000";
    return false;
  }
  if (width < 8 || height < 8 || width > 20000 || height > 20000) {
    *why = "image size must be 8 to 20000 pixels a side";
    return false;
  }
  if (!(fill_light >= 0.0 && fill_light < 1.0)) {
    *why = "fill_light must be in [0, 1)";
    return false;
  }
  if (!(frame_fraction > 0.0 && frame_fraction <= 1.0) || !(exposure_target > 0.0 && exposure_target <= 1.0)) {
    *why = "frame_fraction and exposure_target must be in (0, 1]";
    return false;
  }
  if ((light_intensity.array() < 0.0).any() || !(light_intensity.maxCoeff() > 0.0)) {
    *why = "light_intensity must be non-negative and not all zero";
    return false;
  }
  if (targets) {
    if (!(target_ring_radius > bounding + target_size)) {
      *why = "targets: the marker ring must lie outside the sample";
      return false;
    }
    if (target_count < 1 || !(target_size > 0.0) || !(platform_radius > target_ring_radius + target_size)) {
      *why = "targets: need at least one marker, a positive size, and a platform wider than the ring";
      return false;
    }
    if (!(target_white > target_black && target_black >= 0.0 && target_white <= 1.0)) {
      *why = "targets: need 0 <= target_black < target_white <= 1";
      return false;
    }
    if (light_target_photos < 0 ||
        (light_target_photos > 0 &&
         (light_marker_count < 1 || light_marker_first_id < target_count || !(light_marker_size > 0.0) ||
          !(light_card_drop > 0.5 * light_marker_size * (1.0 + 2.0 * card_margin))))) {
      *why = "targets: light markers need ids above the ring's, a positive size, and a card below the light";
      return false;
    }
  }
  if (!radiometry.Check(why)) return false;
  return effects.Check(why);
}

Image RenderRadiance(const Session& session, size_t photo_index, const BrdfModel& material, int supersample,
                     std::vector<uint8_t>* hit_mask) {
  const std::unique_ptr<AnalyticSample> sample = AnalyticSample::Create(session.sample);
  return RenderRadianceImpl(session, photo_index, *sample, false, material, supersample, hit_mask, nullptr,
                            Eigen::Vector3d::Zero());
}

Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask) {
  return RenderRadianceImpl(session, photo_index, truth, shadow_rays, material, supersample, hit_mask, nullptr,
                            Eigen::Vector3d::Zero());
}

namespace {
Image RenderRadianceImpl(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                         const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask,
                         uint64_t* shadowed_pixels, const Eigen::Vector3d& fill_irradiance) {
  const Camera& camera = session.camera;
  const AnalyticSample* sample = &truth;
  std::atomic<uint64_t> shadowed{0};
  const Rigid3d world_from_camera = session.photos[photo_index].camera_from_world->Inverse();
  const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d center = world_from_camera.translation;
  Image image(camera.width, camera.height, 3);
  if (hit_mask) hit_mask->assign(size_t(camera.width) * camera.height, 0);
  const double weight = 1.0 / (supersample * supersample);
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < camera.width; ++x) {
        Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
        for (int sy = 0; sy < supersample; ++sy) {
          for (int sx = 0; sx < supersample; ++sx) {
            const Eigen::Vector2d pixel(x + (sx + 0.5) / supersample, y + (sy + 0.5) / supersample);
            const Eigen::Vector2d xy = camera.CamPlaneFromImage(pixel);
            const Eigen::Vector3d direction = (rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
            SurfaceHit hit;
            if (!sample->Intersect(center, direction, &hit)) continue;
            const bool centre_ray = sx == supersample / 2 && sy == supersample / 2;
            if (hit_mask && centre_ray) (*hit_mask)[size_t(y) * camera.width + x] = 1;
            const LocalFrame frame = LocalFrame::FromNormal(hit.normal);
            const Eigen::Vector3d wo = frame.ToLocal(-direction);
            // The fill light (SynthOptions::fill_light) reaches every point, shadowed or not.
            if (fill_irradiance.any()) {
              radiance += weight * material.Eval(Eigen::Vector3d::UnitZ(), wo).cwiseProduct(fill_irradiance);
            }
            const Incidence incidence = IncidenceAt(session.light, hit.point, hit.normal);
            if (!incidence.lit) continue;
            if (shadow_rays) {
              // The shadow ray starts 2 micrometres off the surface (outside the solid) and is blocked
              // by any hit nearer than the light.
              SurfaceHit blocker;
              if (sample->Intersect(hit.point + 2e-6 * hit.normal, incidence.wi, &blocker) &&
                  blocker.t < incidence.distance) {
                if (centre_ray) ++shadowed;
                continue;
              }
            }
            const Eigen::Vector3d f = material.Eval(frame.ToLocal(incidence.wi), wo);
            radiance += weight * f.cwiseProduct(incidence.irradiance);
          }
        }
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(radiance[c]);
      }
    }
  });
  if (shadowed_pixels) *shadowed_pixels += shadowed;
  return image;
}
}  // namespace

namespace {
// Writes an irregular shape's scan files (scan/view-N.ply in the scanner's frame), truth-mesh.ply, and
// the mesh sample into `root`/session.json; returns the geometry's truth (truth.json "generator"."geometry").
nlohmann::json WriteShapeFiles(const SynthOptions& options, const ImplicitSample& shape, const std::string& root,
                               SampleSpec* sample, SynthSummary* summary) {
  const Rigid3d scan_from_world = ScanFromWorld(options);
  const RayCaster caster = [&shape](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* t,
                                    Eigen::Vector3d* normal) {
    SurfaceHit hit;
    if (!shape.Intersect(origin, direction, &hit)) return false;
    *t = hit.t;
    *normal = hit.normal;
    return true;
  };
  RangeScannerOptions scanner = options.scanner;
  scanner.seed = options.seed;
  const std::vector<ScanMesh> views =
      SimulateRangeScans(caster, shape.BoundingCenter(), shape.BoundingRadius(), scanner, scan_from_world);
  fs::create_directories(fs::path(root) / "scan");
  sample->scan_inputs.clear();
  for (size_t v = 0; v < views.size(); ++v) {
    const std::string name = "scan/view-" + std::to_string(v) + ".ply";
    WriteRangeGridPly((fs::path(root) / name).string(), views[v]);
    ScanInputSpec input;
    input.file = name;
    sample->scan_inputs.push_back(input);
    summary->scan_points += views[v].points.size();
  }
  summary->scan_views = static_cast<int>(views.size());
  // The scanner's measurement of the platform's markers: their corners in its frame, with noise.
  std::mt19937_64 rng(options.seed * 0x9E3779B97F4A7C15ull + 0x5CA4);
  std::normal_distribution<double> noise(0.0, 1.0);
  sample->scan_targets.clear();
  for (const TargetSpec& target : TargetLayout(options)) {
    ScanTargetSpec measured;
    measured.id = target.id;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d error(noise(rng), noise(rng), noise(rng));
      measured.corners[k] = scan_from_world * target.corners[k] + options.scan_target_noise_m * error;
    }
    sample->scan_targets.push_back(measured);
  }
  WritePly((fs::path(root) / kTruthMesh).string(), TruthMesh(shape, options.truth_mesh_spacing_m));
  const RangeScannerOptions& s = scanner;
  return {{"shape", shape.Describe()},
          {"truth_mesh", kTruthMesh},
          {"scan_from_world", RigidJson(scan_from_world)},
          {"world_from_scan", RigidJson(scan_from_world.Inverse())},
          {"scan_target_noise_m", options.scan_target_noise_m},
          {"scanner",
           {{"views_around", s.views_around},
            {"around_elevation_deg", s.around_elevation_deg},
            {"view_above", s.view_above},
            {"distance_m", s.distance_m},
            {"spacing_m", s.spacing_m},
            {"noise_m", s.noise_m},
            {"max_view_angle_deg", s.max_view_angle_deg}}}};
}
}  // namespace

std::string SynthSummary::BriefReport() const {
  char buffer[320];
  const int n = std::snprintf(buffer, sizeof(buffer), "synth: %d photos in %.2f s; %llu pixels clipped at saturation",
                              photos, total_s, static_cast<unsigned long long>(saturated_pixels));
  if (scan_views > 0) {
    std::snprintf(
        buffer + n, sizeof(buffer) - n, "; %llu pixels in the shape's own shadow; %d range scans, %llu points",
        static_cast<unsigned long long>(shadowed_pixels), scan_views, static_cast<unsigned long long>(scan_points));
  }
  return buffer;
}

SynthSummary WriteSyntheticSession(const SynthOptions& options, const BrdfModel& material,
                                   const std::string& material_name, const std::string& out_dir, bool overwrite) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("synth options", why);
  SynthSummary summary;
  Session session = BuildSession(options);
  session.name = fs::path(out_dir).filename().string();
  AtomicDirectory directory(out_dir, overwrite);
  fs::create_directories(fs::path(directory.temporary_path()) / "photos");

  const CameraEffects& effects = options.effects;
  std::atomic<uint64_t> saturated{0};
  uint64_t shadowed = 0;
  const std::unique_ptr<AnalyticSample> truth = TrueSample(options, session);
  const bool shadow_rays = options.shape != SynthOptions::Shape::kNone;
  // The fill light's irradiance: fill_light times the point light's at the sample's centre, head on.
  const Eigen::Vector3d centre = truth->BoundingCenter();
  const Eigen::Vector3d to_light = IncidenceAt(session.light, centre, Eigen::Vector3d::UnitZ()).wi;
  const Eigen::Vector3d fill_irradiance = options.fill_light * IncidenceAt(session.light, centre, to_light).irradiance;
  ProgressBar progress("photos", session.photos.size());
  std::unique_ptr<TargetScene> scene;
  if (options.targets) scene = std::make_unique<TargetScene>(options);
  // Photos one after another; each renders and adds noise in parallel over rows.
  for (size_t i = 0; i < session.photos.size(); ++i) {
    std::vector<uint8_t> mask;
    Image image =
        RenderRadianceImpl(session, i, *truth, shadow_rays, material, effects.supersample, &mask,
                           session.photos[i].role == PhotoRole::kMeasurement ? &shadowed : nullptr, fill_irradiance);
    // Auto-exposure: the 99th percentile of the brightest channel over the sample's pixels.
    std::vector<float> levels;
    for (size_t p = 0; p < mask.size(); ++p) {
      if (!mask[p]) continue;
      const float* rgb = &image.pixels[p * 3];
      const float level = std::max({rgb[0], rgb[1], rgb[2]});
      if (level > 0.0f) levels.push_back(level);
    }
    double reference = 1.0;
    if (!levels.empty()) {
      reference = PercentileInPlace(&levels, 0.99);
    }
    PhotoSpec& photo = session.photos[i];
    photo.exposure_s *= options.exposure_target / reference;  // exposure_s holds the bracket's factor (1 without)
    photo.gain = 1.0;

    // Radiance to linear signal, then the platform (its values are already signal).
    for (float& v : image.pixels) v = static_cast<float>(v * photo.exposure_s * photo.gain);
    if (scene) CompositeTargets(session, i, *scene, *truth, mask, &image);
    ApplyVignetting(session.camera, effects.vignetting, &image);
    // The sensor (synthetic_radiometry.h): one random stream per (seed, photo, row).
    saturated += SimulateSensor(effects, options.seed, i, &image);
    const PixelFormat format = effects.bits == 0   ? PixelFormat::kFloat
                               : effects.bits <= 8 ? PixelFormat::kUint8
                                                   : PixelFormat::kUint16;
    WriteImage((fs::path(directory.temporary_path()) / photo.file).string(), image, format);
    progress.Add(1);
  }
  progress.Finish();

  WriteSynthCalibration(options, directory.temporary_path(), &session);  // radiometry hook: flat field, white reference
  // Irregular shapes: the range scan, the truth mesh, and the mesh sample's scan inputs and targets
  // (the sample's file, scan/mesh.ply, is the scan stage's output from those inputs).
  const nlohmann::json shape_truth = options.shape != SynthOptions::Shape::kNone
                                         ? WriteShapeFiles(options, static_cast<const ImplicitSample&>(*truth),
                                                           directory.temporary_path(), &session.sample, &summary)
                                         : nlohmann::json();
  if (!shape_truth.is_null()) summary.shadowed_pixels = shadowed;
  session.Save((fs::path(directory.temporary_path()) / "session.json").string());
  nlohmann::json truth_json = {
      {"format", "ibrdf-truth"},
      {"version", 1},
      {"material_name", material_name},
      {"material", material.ToJson()},
      {"generator",
       {{"sample",
         options.shape != SynthOptions::Shape::kNone ? SynthShapeName(options.shape) : SampleKindName(options.sample)},
        {"sample_radius", options.sample_radius},
        {"cylinder_length", options.cylinder_length},
        {"origin", ToJson(options.origin)},
        {"light_distance", options.light_distance},
        {"camera_distance", options.camera_distance},
        {"camera_elevation_deg", options.camera_elevation_deg},
        {"num_photos", options.num_photos},
        {"arc_start_deg", options.arc_start_deg},
        {"arc_end_deg", options.arc_end_deg},
        {"width", options.width},
        {"height", options.height},
        {"exposure_target", options.exposure_target},
        {"fill_light", options.fill_light},
        {"seed", options.seed},
        {"targets", options.targets},
        {"light_target_photos", options.targets ? options.light_target_photos : 0},
        {"effects",
         {{"shot_noise", effects.shot_noise},
          {"read_noise", effects.read_noise},
          {"full_well_e", effects.full_well_e},
          {"read_noise_e", effects.read_noise_e},
          {"bits", effects.bits},
          {"srgb", effects.srgb},
          {"clip", effects.clip},
          {"black_level", effects.black_level},
          {"supersample", effects.supersample},
          {"vignetting", effects.vignetting}}},
        {"radiometry",
         {{"brackets", options.radiometry.brackets},
          {"bracket_step_ev", options.radiometry.bracket_step_ev},
          {"light_unknown", options.radiometry.light_unknown},
          {"light_intensity", ToJson(options.light_intensity)}}}}},
  };
  if (!shape_truth.is_null()) truth_json["generator"]["geometry"] = shape_truth;
  WriteJsonFile((fs::path(directory.temporary_path()) / "truth.json").string(), truth_json);
  directory.Commit();
  summary.photos = options.num_photos;
  summary.saturated_pixels = saturated;
  summary.total_s = timer.ElapsedSeconds();
  summary.success = true;
  return summary;
}

}  // namespace ibrdf
