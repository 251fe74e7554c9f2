#include "synth/synthetic.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>
#include <nlohmann/json.hpp>

#include "align/markers.h"
#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_brdf.h"
#include "core/radiometry.h"
#include "core/statistics.h"
#include "derender/analytic_sample.h"
#include "scan/ply_io.h"
#include "synth/photo_png.h"
#include "synth/pixel_rays.h"
#include "synth/synthetic_colour_chart.h"
#include "synth/synthetic_exif.h"
#include "synth/synthetic_radiometry.h"
#include "synth/synthetic_targets.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The response a session states for photos written through `curve`: the curve itself (a 4097-entry
// table for the toe-and-shoulder curve, exact to 1e-6 relative by linear interpolation), or "unknown".
Response SessionResponse(SensorCurve curve, bool unknown) {
  Response response;
  if (unknown) {
    response.kind = Response::Kind::kUnknown;
    return response;
  }
  switch (curve) {
    case SensorCurve::kLinear:
      response.kind = Response::Kind::kLinear;
      break;
    case SensorCurve::kSrgb:
      response.kind = Response::Kind::kSrgb;
      break;
    case SensorCurve::kToeShoulder: {
      response.kind = Response::Kind::kTable;
      constexpr int kEntries = 4097;
      for (int i = 0; i < kEntries; ++i) response.table.push_back(ToeShoulderDecode(double(i) / (kEntries - 1)));
      break;
    }
  }
  return response;
}

// Where an irregular-shape session keeps its scan (relative to the session folder).
constexpr char kScanMesh[] = "scan/mesh.ply";
constexpr char kTruthMesh[] = "truth-mesh.ply";

// The true shape a session renders: the irregular shape, or the session's own sphere or cylinder.
std::unique_ptr<AnalyticSample> TrueSample(const SynthOptions& options, const Session& session) {
  if (options.scene.shape != SynthShape::kNone) return MakeTrueShape(options.scene);
  return AnalyticSample::Create(session.sample);
}

// The arc's one light: a point light along +x at light_distance.
Light ArcLight(const SynthOptions& options) {
  Light light;
  light.kind = Light::Kind::kPoint;
  light.position = options.scene.origin + options.scene.light_distance * Eigen::Vector3d::UnitX();
  light.intensity = options.scene.light_intensity;
  return light;
}

// A unit direction at `azimuth` and `elevation` (radians) about the vertical.
Eigen::Vector3d Direction(double azimuth, double elevation) {
  return Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                         std::sin(elevation));
}

// Photo i's file name.
std::string PhotoFile(const SynthOptions& options, int i) {
  char name[32];
  std::snprintf(name, sizeof(name), "photos/%03d.%s", i, options.effects.bits == 0 ? "exr" : "png");
  return name;
}

// The measurement photos: cameras on the arc, evenly spaced in azimuth from the light direction.
std::vector<PhotoSpec> ArcPhotos(const SynthOptions& options) {
  std::vector<PhotoSpec> photos;
  const double elevation = options.rig.camera_elevation_deg * kDegree;
  for (int i = 0; i < options.rig.num_photos; ++i) {
    const double t = options.rig.num_photos == 1 ? 0.0 : double(i) / (options.rig.num_photos - 1);
    const double azimuth =
        (options.rig.arc_start_deg + t * (options.rig.arc_end_deg - options.rig.arc_start_deg)) * kDegree;
    const Eigen::Vector3d direction = Direction(azimuth, elevation);
    PhotoSpec photo;
    photo.file = PhotoFile(options, i);
    photo.camera_from_world = LookAtCameraFromWorld(options.scene.origin + options.rig.camera_distance * direction,
                                                    options.scene.origin, Eigen::Vector3d::UnitZ());
    photos.push_back(photo);
  }
  for (size_t n = 0; n < options.rig.extra_camera_positions.size(); ++n) {
    PhotoSpec photo;
    photo.file = PhotoFile(options, options.rig.num_photos + int(n));
    photo.camera_from_world = LookAtCameraFromWorld(options.rig.extra_camera_positions[n], options.scene.origin,
                                                    Eigen::Vector3d::UnitZ());
    photos.push_back(photo);
  }
  return photos;
}

// The dome's light directions: n points of a Fibonacci spiral (equal area) over the band of the
// upper hemisphere above dome_min_elevation_deg, keeping those whose angle from the camera lies in
// [arc_start_deg, arc_end_deg]; the spiral is made denser until exactly num_photos are kept.
std::vector<Eigen::Vector3d> DomeLightDirections(const SynthOptions& options, const Eigen::Vector3d& to_camera) {
  const SynthRigOptions& rig = options.rig;
  const double z_min = std::sin(rig.dome_min_elevation_deg * kDegree);
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  for (int n = rig.num_photos; n < 64 * rig.num_photos + 64; ++n) {
    std::vector<Eigen::Vector3d> kept;
    for (int k = 0; k < n; ++k) {
      const double z = 1.0 - (1.0 - z_min) * (k + 0.5) / n;  // equal-area bands from the zenith down
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const Eigen::Vector3d d(r * std::cos(golden_angle * k), r * std::sin(golden_angle * k), z);
      const double angle = std::acos(std::clamp(d.dot(to_camera), -1.0, 1.0)) / kDegree;
      if (angle >= rig.arc_start_deg && angle <= rig.arc_end_deg) kept.push_back(d);
    }
    if (static_cast<int>(kept.size()) == rig.num_photos) return kept;
  }
  ThrowError("synth --rig dome", "cannot place " + std::to_string(rig.num_photos) + " lights between " +
                                     std::to_string(rig.arc_start_deg) + " and " + std::to_string(rig.arc_end_deg) +
                                     " degrees from the camera");
}

// The measurement photos and the lights of the rig (SynthRig): the arc's cameras under one light, the
// dome's one camera under a light per photo, or the turntable's poses and lights in the sample's frame.
void RigPhotosAndLights(const SynthOptions& options, Session* session) {
  const SynthRigOptions& rig = options.rig;
  const Eigen::Vector3d& origin = options.scene.origin;
  const double elevation = rig.camera_elevation_deg * kDegree;
  switch (rig.rig) {
    case SynthRig::kArc:
      session->lights = {ArcLight(options)};
      session->photos = ArcPhotos(options);
      return;
    case SynthRig::kDome: {
      const Eigen::Vector3d to_camera = Direction(0.0, elevation);
      const Rigid3d camera_from_world =
          LookAtCameraFromWorld(origin + rig.camera_distance * to_camera, origin, Eigen::Vector3d::UnitZ());
      const std::vector<Eigen::Vector3d> directions = DomeLightDirections(options, to_camera);
      session->lights.clear();
      session->photos.clear();
      for (int i = 0; i < rig.num_photos; ++i) {
        Light light;
        char id[16];
        std::snprintf(id, sizeof(id), "D%02d", i);
        light.id = id;
        light.kind = Light::Kind::kPoint;
        light.position = origin + options.scene.light_distance * directions[i];
        light.intensity = options.scene.light_intensity;
        session->lights.push_back(light);
        PhotoSpec photo;
        photo.file = PhotoFile(options, i);
        photo.camera_from_world = camera_from_world;
        photo.light = i;
        session->photos.push_back(photo);
      }
      return;
    }
    case SynthRig::kTurntable: {
      // In the lab: the light along +x, the camera at turntable_phase_deg from it. The sample turns by
      // `angle` about the vertical through its centre: lab_from_sample = R(angle) about `origin`.
      const Eigen::Vector3d light_in_lab = origin + options.scene.light_distance * Eigen::Vector3d::UnitX();
      const Rigid3d camera_from_lab =
          LookAtCameraFromWorld(origin + rig.camera_distance * Direction(rig.turntable_phase_deg * kDegree, elevation),
                                origin, Eigen::Vector3d::UnitZ());
      const bool full_turn = rig.turntable_span_deg >= 360.0;
      session->lights.clear();
      session->photos.clear();
      for (int i = 0; i < rig.num_photos; ++i) {
        const double steps = full_turn ? rig.num_photos : std::max(1, rig.num_photos - 1);
        const double angle = rig.turntable_span_deg * kDegree * i / steps;
        const Eigen::Quaterniond rotation(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
        const Rigid3d lab_from_sample(rotation, origin - rotation * origin);
        const Rigid3d sample_from_lab = lab_from_sample.Inverse();
        Light light;
        char id[16];
        std::snprintf(id, sizeof(id), "T%03d", i);
        light.id = id;
        light.kind = Light::Kind::kPoint;
        light.position = sample_from_lab * light_in_lab;
        light.intensity = options.scene.light_intensity;
        session->lights.push_back(light);
        PhotoSpec photo;
        photo.file = PhotoFile(options, i);
        photo.camera_from_world = camera_from_lab * lab_from_sample;
        photo.light = i;
        session->photos.push_back(photo);
      }
      return;
    }
  }
}

// The light-target photos (role "targets"): from behind and above the sample, opposite the light, looking past the
// sample at the light's card, turned so the long side of the frame runs from the platform to the card; spread sideways
// (0.25 m apart) so the card's markers are seen from several directions. None without targets.
std::vector<PhotoSpec> LightTargetPhotos(const SynthOptions& options) {
  std::vector<PhotoSpec> photos;
  const CameraEffects& effects = options.effects;
  if (options.targets.enabled && options.targets.light_photos > 0) {
    const int n = options.targets.light_photos;
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
          roll * LookAtCameraFromWorld(options.scene.origin + Eigen::Vector3d(-0.7, lateral, 0.55),
                                       options.scene.origin + Eigen::Vector3d(0.35, -0.2 * lateral, -0.1),
                                       -Eigen::Vector3d::UnitY());
      photos.push_back(photo);
    }
  }
  return photos;
}

// The session (camera, light, sample, poses) an options object describes, without photos on disk.
Session BuildSession(const SynthOptions& options) {
  Session session;
  SampleSpec& sample = session.sample;
  double bounding_radius = 0.0;
  if (options.scene.shape != SynthShape::kNone) {
    sample.kind = SampleSpec::Kind::kMesh;
    sample.mesh_file = kScanMesh;
    bounding_radius = MakeTrueShape(options.scene)->BoundingRadius();
  } else {
    sample.kind = options.scene.sample;
    sample.center = options.scene.origin;
    sample.radius = options.scene.sample_radius;
    switch (sample.kind) {
      case SampleSpec::Kind::kSphere:
        break;
      case SampleSpec::Kind::kCylinder:
        sample.axis = Eigen::Vector3d::UnitZ();
        sample.length = options.scene.cylinder_length;
        break;
      case SampleSpec::Kind::kMesh:
        UnhandledKind("SampleSpec::Kind", static_cast<int>(sample.kind));  // a shape, handled above
    }
    bounding_radius = AnalyticSample::Create(sample)->BoundingRadius();
  }

  RigPhotosAndLights(options, &session);

  const double framed_radius =
      options.targets.enabled ? std::max(bounding_radius, options.targets.platform_radius) : bounding_radius;
  const double half_angle = std::asin(std::min(1.0, framed_radius / options.rig.camera_distance));
  const double focal =
      options.rig.frame_fraction * 0.5 * std::min(options.rig.width, options.rig.height) / std::tan(half_angle);
  session.camera = Camera::Create(CameraModelId::kOpenCV, options.rig.width, options.rig.height,
                                  {focal, focal, 0.5 * options.rig.width, 0.5 * options.rig.height, options.rig.k1,
                                   options.rig.k2, options.rig.p1, options.rig.p2},
                                  "synth camera");

  const CameraEffects& effects = options.effects;
  session.radiometry.response = SessionResponse(effects.curve, options.radiometry.response_unknown);
  session.radiometry.black_level = effects.black_level;
  // Unclipped files state no saturation level (float files then have none; radiometry/linear_image.h).
  session.radiometry.saturation_stated = effects.clip;
  session.radiometry.saturation_level = 1.0;
  if (effects.shot_noise || effects.read_noise || effects.bits > 0) {
    CameraNoise noise;
    noise.full_well_e = effects.full_well_e;
    noise.read_noise_e = effects.read_noise ? effects.read_noise_e : 0.0;
    noise.bits = effects.bits;
    if (!effects.shot_noise) noise.full_well_e = 1e30;  // no shot noise: an infinitely deep well
    session.radiometry.noise = noise;
  }

  if (options.targets.enabled) {
    TargetsSpec targets;
    targets.dictionary = options.targets.dictionary;
    targets.reference = TargetLayout(options);
    const SampleTargetsSpec sample_targets = SampleTargetLayout(options, nullptr);
    if (!sample_targets.markers.empty()) targets.sample = sample_targets;
    const LightTargetsSpec light = LightTargetLayout(options, nullptr);
    if (!light.markers.empty()) targets.light = light;
    if (options.targets.white_card) targets.white_reference = SynthWhiteCardLayout(options);
    session.targets = targets;
  }

  const std::vector<PhotoSpec> target_photos = LightTargetPhotos(options);
  session.photos.insert(session.photos.end(), target_photos.begin(), target_photos.end());
  ExpandBrackets(options, &session);  // radiometry hook: exposure brackets
  return session;
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
      : options_(options), dictionary_(options.targets.dictionary, "synth --target-dictionary") {
    Board platform;
    platform.center =
        Eigen::Vector3d(options.scene.origin.x(), options.scene.origin.y(), PlatformHeight(options.scene));
    platform.radius = options.targets.platform_radius;
    platform.background = options.targets.black;
    platform.markers = TargetLayout(options);
    boards_.push_back(platform);
    std::vector<TargetSpec> light_markers;
    LightTargetLayout(options, &light_markers);
    if (!light_markers.empty()) {
      // The card: the markers' cards side by side, in the plane through the light facing the sample.
      Board card;
      const Eigen::Vector3d light = options.scene.origin + options.scene.light_distance * Eigen::Vector3d::UnitX();
      card.center = light - options.targets.light_card_drop * Eigen::Vector3d::UnitZ();
      card.normal = Eigen::Vector3d::UnitX();
      card.u_axis = Eigen::Vector3d::UnitY();
      card.v_axis = Eigen::Vector3d::UnitZ();
      const double pitch = options.targets.light_marker_size * (1.0 + 2.0 * options.targets.card_margin);
      card.half_u = 0.5 * pitch * options.targets.light_marker_count;
      card.half_v = 0.5 * pitch;
      card.background = options.targets.white;
      card.markers = light_markers;
      boards_.push_back(card);
    }
    std::vector<TargetSpec> sample_markers;
    SampleTargetLayout(options, &sample_markers);
    if (!sample_markers.empty()) {
      // The cylinder's top cap: a black disk carrying the sample's markers.
      Board cap;
      cap.center = options.scene.origin + 0.5 * options.scene.cylinder_length * Eigen::Vector3d::UnitZ();
      cap.radius = options.scene.sample_radius;
      cap.background = options.targets.black;
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
      const double margin = options_.targets.card_margin;
      if (u < -margin || u >= 1.0 + margin || v < -margin || v >= 1.0 + margin) continue;
      if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) return options_.targets.white;  // the card's border
      const int col = std::min(n - 1, int(u * n)), row = std::min(n - 1, int(v * n));
      return board.modules[m][size_t(row) * n + col] ? options_.targets.white : options_.targets.black;
    }
    return board.background;
  }

  const SynthOptions& options_;
  MarkerDictionary dictionary_;
  std::vector<Board> boards_;
};

// Composites the target boards into a photo's linear signal where the pixel is not in `skip_mask`
// (the sample's pixel centres; empty: none): 4 x 4 rays per pixel, the boards' fraction of them
// averaged (sharp, anti-aliased marker edges). A ray that `in_front` hits before the board sees nothing
// of it (the sample, or the white reference's card).
void CompositeTargets(const Camera& camera, const Rigid3d& camera_from_world, const TargetScene& scene,
                      const TargetOccluder& in_front, const std::vector<uint8_t>& skip_mask, Image* signal) {
  const CameraRay camera_ray(camera, camera_from_world);
  const Eigen::Vector3d& center = camera_ray.eye();
  // The boards' value along a ray through an image point; 0 where it shows nothing (or the sample
  // is in front).
  auto value_at = [&](const Eigen::Vector2d& pixel) {
    const Eigen::Vector3d direction = camera_ray.Direction(pixel);
    double t;
    const double value = scene.Trace(center, direction, &t);
    if (!(value > 0.0)) return 0.0;
    if (in_front && in_front(center, direction, t)) return 0.0;
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
      if (!skip_mask.empty() && skip_mask[size_t(y) * w + x]) continue;
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

// What a session's surface is made of: one material, or (map non-null) a material map, whose
// Eval takes the hit's world point; `material` is then null.
struct SurfaceMaterial {
  const BrdfModel* material = nullptr;
  const MaterialMap* map = nullptr;
};

Image RenderRadianceImpl(const Session& session, size_t photo_index, const PixelRays& rays, const AnalyticSample& truth,
                         bool shadow_rays, const SurfaceMaterial& surface, std::vector<uint8_t>* hit_mask,
                         uint64_t* shadowed_pixels, const Eigen::Vector3d& fill_irradiance,
                         std::vector<uint8_t>* no_data_mask);

}  // namespace

std::unique_ptr<ImplicitSample> MakeTrueShape(const SynthSceneOptions& scene) {
  switch (scene.shape) {
    case SynthShape::kNone:
      return nullptr;
    case SynthShape::kSquash:
      return std::make_unique<SquashSample>(scene.origin, scene.squash);
    case SynthShape::kPot:
      return std::make_unique<PotSample>(scene.origin, scene.pot);
    case SynthShape::kDent:
      return std::make_unique<DentedSphereSample>(scene.origin, scene.dent);
  }
  return nullptr;
}

Rigid3d ScanFromWorld(const SynthScanOptions& scan) {
  const Eigen::Quaterniond rotation(Eigen::AngleAxisd(35.0 * kDegree, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  return Rigid3d(rotation, scan.offset_m * Eigen::Vector3d(0.6, -0.48, 0.64));
}

Image RenderRadiance(const Session& session, size_t photo_index, const BrdfModel& material, int supersample,
                     std::vector<uint8_t>* hit_mask) {
  const std::unique_ptr<AnalyticSample> sample = AnalyticSample::Create(session.sample);
  return RenderRadianceImpl(session, photo_index, PixelRays(session.camera, supersample), *sample, false,
                            SurfaceMaterial{&material, nullptr}, hit_mask, nullptr, Eigen::Vector3d::Zero(), nullptr);
}

Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask) {
  return RenderRadianceImpl(session, photo_index, PixelRays(session.camera, supersample), truth, shadow_rays,
                            SurfaceMaterial{&material, nullptr}, hit_mask, nullptr, Eigen::Vector3d::Zero(), nullptr);
}

Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const MaterialMap& map, int supersample, std::vector<uint8_t>* hit_mask) {
  return RenderRadianceImpl(session, photo_index, PixelRays(session.camera, supersample), truth, shadow_rays,
                            SurfaceMaterial{nullptr, &map}, hit_mask, nullptr, Eigen::Vector3d::Zero(), nullptr);
}

namespace {
// `no_data_mask` (optional) gets 1 where a ray of the pixel looked up a cell without data of a tabulated
// material (a MERL table's negative cell; such a lookup evaluates to 0); all 0 for other materials.
Image RenderRadianceImpl(const Session& session, size_t photo_index, const PixelRays& rays, const AnalyticSample& truth,
                         bool shadow_rays, const SurfaceMaterial& surface, std::vector<uint8_t>* hit_mask,
                         uint64_t* shadowed_pixels, const Eigen::Vector3d& fill_irradiance,
                         std::vector<uint8_t>* no_data_mask) {
  const Camera& camera = session.camera;
  const Light& light = session.PhotoLight(photo_index);
  const AnalyticSample* sample = &truth;
  std::atomic<uint64_t> shadowed{0};
  if (hit_mask) hit_mask->assign(size_t(camera.width) * camera.height, 0);
  if (no_data_mask) no_data_mask->assign(size_t(camera.width) * camera.height, 0);
  const bool fill = fill_irradiance.any();
  const BrdfModel* material = surface.material;
  const MaterialMap* map = surface.map;
  IBRDF_CHECK((material == nullptr) != (map == nullptr));
  const auto* table = no_data_mask && material ? dynamic_cast<const MerlBrdf*>(material) : nullptr;
  // The surface's BRDF at the world point `point` for (wi, wo), marking the pixel where a table's lookup
  // found no data (MerlBrdf::Eval's test). One pointer test per call keeps the single material's path as
  // it was.
  auto eval = [&](const Eigen::Vector3d& point, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo,
                  const PixelRay& ray) -> Eigen::Vector3d {
    if (map) return map->Eval(point, wi, wo);
    if (table && wi.z() > 0.0 && wo.z() > 0.0 &&
        (table->Lookup(wi.normalized(), wo.normalized()).array() < 0.0).any()) {
      (*no_data_mask)[ray.pixel] = 1;
    }
    return material->Eval(wi, wo);
  };
  Image image = RenderRays(rays, *session.photos[photo_index].camera_from_world,
                           [&](const Eigen::Vector3d& eye, const PixelRay& ray) -> Eigen::Vector3d {
                             SurfaceHit hit;
                             if (!sample->Intersect(eye, ray.direction, &hit)) return Eigen::Vector3d::Zero();
                             if (hit_mask && ray.centre) (*hit_mask)[ray.pixel] = 1;
                             const LocalFrame frame = LocalFrame::FromNormal(hit.normal);
                             const Eigen::Vector3d wo = frame.ToLocal(-ray.direction);
                             Eigen::Vector3d radiance = Eigen::Vector3d::Zero();
                             // The fill light (SynthOptions::fill_light) reaches every point, shadowed or not.
                             if (fill) {
                               radiance +=
                                   eval(hit.point, Eigen::Vector3d::UnitZ(), wo, ray).cwiseProduct(fill_irradiance);
                             }
                             const Incidence incidence = IncidenceAt(light, hit.point, hit.normal);
                             if (!incidence.lit) return radiance;
                             if (shadow_rays) {
                               // The shadow ray starts 2 micrometres off the surface (outside the solid)
                               // and is blocked by any hit nearer than the light.
                               SurfaceHit blocker;
                               if (sample->Intersect(hit.point + 2e-6 * hit.normal, incidence.wi, &blocker) &&
                                   blocker.t < incidence.distance) {
                                 if (ray.centre) ++shadowed;
                                 return radiance;
                               }
                             }
                             const Eigen::Vector3d f = eval(hit.point, frame.ToLocal(incidence.wi), wo, ray);
                             return Eigen::Vector3d(radiance + f.cwiseProduct(incidence.irradiance));
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
  const Rigid3d scan_from_world = ScanFromWorld(options.scan);
  const RayCaster caster = [&shape](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* t,
                                    Eigen::Vector3d* normal) {
    SurfaceHit hit;
    if (!shape.Intersect(origin, direction, &hit)) return false;
    *t = hit.t;
    *normal = hit.normal;
    return true;
  };
  RangeScannerOptions scanner = options.scan.scanner;
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
      measured.corners[k] = scan_from_world * target.corners[k] + options.scan.target_noise_m * error;
    }
    sample->scan_targets.push_back(measured);
  }
  WritePly((fs::path(root) / kTruthMesh).string(), TruthMesh(shape, options.scan.truth_mesh_spacing_m));
  const RangeScannerOptions& s = scanner;
  return {{"shape", shape.Describe()},
          {"truth_mesh", kTruthMesh},
          {"scan_from_world", RigidJson(scan_from_world)},
          {"world_from_scan", RigidJson(scan_from_world.Inverse())},
          {"scan_target_noise_m", options.scan.target_noise_m},
          {"scanner",
           {{"views_around", s.views_around},
            {"around_elevation_deg", s.around_elevation_deg},
            {"view_above", s.view_above},
            {"distance_m", s.distance_m},
            {"spacing_m", s.spacing_m},
            {"noise_m", s.noise_m},
            {"max_view_angle_deg", s.max_view_angle_deg}}}};
}
// Auto-exposure: the 99th percentile of the brightest channel over the sample's pixels (1 for none).
double AutoExposureReference(const Image& radiance, const std::vector<uint8_t>& mask) {
  std::vector<float> levels;
  for (size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    const float* rgb = &radiance.pixels[p * 3];
    const float level = std::max({rgb[0], rgb[1], rgb[2]});
    if (level > 0.0f) levels.push_back(level);
  }
  return levels.empty() ? 1.0 : PercentileInPlace(&levels, 0.99);
}

// A measurement photo's pixels on a tabulated material's cells without data (`no_data`, from
// RenderRadianceImpl) under options.no_data: counted in `summary`; kSkip writes the photo's mask
// (masks/<photo's stem>.png under `root`, 0 on those pixels, 255 elsewhere) and names it in `photo`;
// kError throws naming the material and the photo.
void ApplyNoDataPolicy(const SynthOptions& options, const std::string& material_name, const Camera& camera,
                       const std::vector<uint8_t>& no_data, const std::string& root, PhotoSpec* photo,
                       SynthSummary* summary) {
  const uint64_t pixels = static_cast<uint64_t>(std::count(no_data.begin(), no_data.end(), uint8_t(1)));
  if (pixels == 0) return;
  summary->no_data_pixels += pixels;
  switch (options.no_data) {
    case SynthNoData::kError:
      ThrowError(material_name, photo->file + ": " + std::to_string(pixels) +
                                    " sample pixels look up cells without data (MERL's -1); --no-data skip leaves "
                                    "them out of the samples, --no-data zero renders them black");
    case SynthNoData::kZero:
      return;
    case SynthNoData::kSkip: {
      Image mask(camera.width, camera.height, 1);
      for (size_t p = 0; p < no_data.size(); ++p) mask.pixels[p] = no_data[p] ? 0.0f : 1.0f;
      const std::string file = "masks/" + fs::path(photo->file).stem().string() + ".png";
      fs::create_directories(fs::path(root) / "masks");
      WriteImage((fs::path(root) / file).string(), mask, PixelFormat::kUint8);
      photo->mask = file;
      ++summary->masked_photos;
      return;
    }
  }
}

// truth.json's "generator": the options that made the session (the keys predate the options' split).
nlohmann::json GeneratorJson(const SynthOptions& options) {
  const CameraEffects& effects = options.effects;
  return {{"sample", options.scene.shape != SynthShape::kNone ? SynthShapeName(options.scene.shape)
                                                              : SampleKindName(options.scene.sample)},
          {"sample_radius", options.scene.sample_radius},
          {"cylinder_length", options.scene.cylinder_length},
          {"origin", ToJson(options.scene.origin)},
          {"light_distance", options.scene.light_distance},
          {"camera_distance", options.rig.camera_distance},
          {"camera_elevation_deg", options.rig.camera_elevation_deg},
          {"num_photos", options.rig.num_photos},
          {"extra_camera_positions", [&] {
             nlohmann::json list = nlohmann::json::array();
             for (const Eigen::Vector3d& p : options.rig.extra_camera_positions) list.push_back(ToJson(p));
             return list;
           }()},
          {"arc_start_deg", options.rig.arc_start_deg},
          {"arc_end_deg", options.rig.arc_end_deg},
          {"rig", SynthRigName(options.rig.rig)},
          {"dome_min_elevation_deg", options.rig.dome_min_elevation_deg},
          {"turntable_phase_deg", options.rig.turntable_phase_deg},
          {"turntable_span_deg", options.rig.turntable_span_deg},
          {"width", options.rig.width},
          {"height", options.rig.height},
          {"exposure_target", options.rig.exposure_target},
          {"fill_light", options.scene.fill_light},
          {"seed", options.seed},
          {"targets", options.targets.enabled},
          {"light_target_photos", options.targets.enabled ? options.targets.light_photos : 0},
          {"effects",
           {{"shot_noise", effects.shot_noise},
            {"read_noise", effects.read_noise},
            {"full_well_e", effects.full_well_e},
            {"read_noise_e", effects.read_noise_e},
            {"bits", effects.bits},
            {"curve", SensorCurveName(effects.curve)},
            {"clip", effects.clip},
            {"black_level", effects.black_level},
            {"supersample", effects.supersample},
            {"vignetting", effects.vignetting}}},
          {"radiometry",
           {{"brackets", options.radiometry.brackets},
            {"bracket_step_ev", options.radiometry.bracket_step_ev},
            {"light_unknown", options.radiometry.light_unknown},
            {"response_unknown", options.radiometry.response_unknown},
            {"light_intensity", ToJson(options.scene.light_intensity)}}}};
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

std::string SynthSummary::NoDataReport() const {
  if (no_data_pixels == 0) return "";
  const std::string head = std::to_string(no_data_pixels) +
                           " sample pixels looked up cells without data in the material's table (MERL's -1; " +
                           std::to_string(table_cells_without_data) + " such cells): ";
  switch (no_data) {
    case SynthNoData::kSkip:
      return head + "rendered black and left out of the samples by the masks of " + std::to_string(masked_photos) +
             " photos (masks/; derender counts them as `masked`)";
    case SynthNoData::kZero:
      return head +
             "rendered as 0 (--no-data zero): derender keeps those that pass its signal floor as near-zero "
             "samples, data the table does not hold";
    case SynthNoData::kError:
      break;
  }
  return head + "refused (--no-data error)";
}

namespace {
// WriteSyntheticSession for one material or a map (`surface`); `material_name` names either.
SynthSummary WriteSession(const SynthOptions& options, const SurfaceMaterial& surface, const std::string& material_name,
                          const std::string& out_dir, bool overwrite) {
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
  const bool shadow_rays = options.scene.shape != SynthShape::kNone;
  // The fill light's irradiance: fill_light times the photo's light's at the sample's centre, head on.
  const Eigen::Vector3d centre = truth->BoundingCenter();
  auto fill_irradiance = [&](size_t i) {
    const Light& light = session.PhotoLight(i);
    const Eigen::Vector3d to_light = IncidenceAt(light, centre, Eigen::Vector3d::UnitZ()).wi;
    return Eigen::Vector3d(options.scene.fill_light * IncidenceAt(light, centre, to_light).irradiance);
  };
  ProgressBar progress("photos", session.photos.size());
  std::unique_ptr<TargetScene> target_scene;
  if (options.targets.enabled) target_scene = std::make_unique<TargetScene>(options);
  // The camera's sub-pixel rays, undistorted once for every photo.
  const PixelRays rays(session.camera, effects.supersample);
  const PixelFormat format = effects.bits == 0   ? PixelFormat::kFloat
                             : effects.bits <= 8 ? PixelFormat::kUint8
                                                 : PixelFormat::kUint16;
  // Photos one after another; each renders and adds noise in parallel over rows, and is written (the
  // PNG encoder is serial) while the next one renders: one photo being written at a time.
  tbb::task_group writing;
  const auto wait_for_writing = [&writing] { writing.wait(); };
  struct WaitOnExit {  // an exception here must not leave a write running into the unwound folder
    tbb::task_group& group;
    ~WaitOnExit() {
      try {
        group.wait();
      } catch (...) {
      }
    }
  } wait_on_exit{writing};
  if (const auto* table = surface.material ? dynamic_cast<const MerlBrdf*>(surface.material) : nullptr) {
    summary.tabulated = true;
    summary.table_cells_without_data = table->cells_without_data();
  }
  summary.no_data = options.no_data;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    std::vector<uint8_t> mask, no_data;
    const bool measurement = session.photos[i].role == PhotoRole::kMeasurement;
    Image image =
        RenderRadianceImpl(session, i, rays, *truth, shadow_rays, surface, &mask, measurement ? &shadowed : nullptr,
                           fill_irradiance(i), measurement && summary.tabulated ? &no_data : nullptr);
    if (!no_data.empty()) {
      ApplyNoDataPolicy(options, material_name, session.camera, no_data, directory.temporary_path(), &session.photos[i],
                        &summary);
    }
    ApplyCameraMatrix(options.colour.camera_matrix, &image);  // colour hook: the camera's RGB
    PhotoSpec& photo = session.photos[i];
    photo.exposure_s *= options.rig.exposure_target /
                        AutoExposureReference(image, mask);  // exposure_s holds the bracket's factor (1 without)
    photo.gain = 1.0;

    // Radiance to linear signal, then the platform (its values are already signal).
    for (float& v : image.pixels) v = static_cast<float>(v * photo.exposure_s * photo.gain);
    if (target_scene) {
      const TargetOccluder sample_in_front = [&truth](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                                      double t) {
        SurfaceHit hit;
        return truth->Intersect(origin, direction, &hit) && hit.t < t;
      };
      // Supersampled, a pixel on the sample's silhouette holds the sample's share of its area, so the
      // platform adds the rest (its uncovered share); a pixel-centre render keeps the sample's pixels whole.
      CompositeTargets(session.camera, *photo.camera_from_world, *target_scene, sample_in_front,
                       effects.supersample > 1 ? std::vector<uint8_t>() : mask, &image);
    }
    ApplyVignetting(session.camera, effects.vignetting, &image);
    // The sensor (synthetic_radiometry.h): one random stream per (seed, photo, row).
    saturated += SimulateSensor(effects, options.seed, i, &image);
    const PhotoMetadata exif = SyntheticPhotoMetadata(session, photo, i);
    const std::string path = (fs::path(directory.temporary_path()) / photo.file).string();
    wait_for_writing();
    writing.run([&progress, image = std::move(image), exif, path, format] {
      WritePhotoPng(path, image, format, &exif);  // libpng directly, without OpenImageIO
      progress.Add(1);
    });
  }
  wait_for_writing();
  progress.Finish();

  // Radiometry hook: flat field, white reference (with the platform behind its card).
  const TargetCompositor composite_targets = [&](const Rigid3d& camera_from_world, const TargetOccluder& card,
                                                 Image* signal) {
    if (target_scene) CompositeTargets(session.camera, camera_from_world, *target_scene, card, {}, signal);
  };
  WriteSynthCalibration(options, directory.temporary_path(), &session, composite_targets);
  const nlohmann::json colour_truth = WriteSynthColour(options, directory.temporary_path(), &session);  // colour hook
  // Irregular shapes: the range scan, the truth mesh, and the mesh sample's scan inputs and targets
  // (the sample's file, scan/mesh.ply, is the scan stage's output from those inputs).
  const nlohmann::json shape_truth = options.scene.shape != SynthShape::kNone
                                         ? WriteShapeFiles(options, static_cast<const ImplicitSample&>(*truth),
                                                           directory.temporary_path(), &session.sample, &summary)
                                         : nlohmann::json();
  if (!shape_truth.is_null()) summary.shadowed_pixels = shadowed;
  session.Save((fs::path(directory.temporary_path()) / "session.json").string());
  nlohmann::json truth_json = {{"format", "ibrdf-truth"}, {"version", 1}};
  if (surface.map) {
    // No single material is the truth: the map (materials embedded) gives it point by point.
    truth_json["material_map_name"] = material_name;
    truth_json["material_map"] = surface.map->ToJson();
  } else {
    truth_json["material_name"] = material_name;
    truth_json["material"] = surface.material->ToJson();
  }
  truth_json["generator"] = GeneratorJson(options);
  if (!shape_truth.is_null()) truth_json["generator"]["geometry"] = shape_truth;
  if (!colour_truth.is_null()) truth_json["generator"]["colour"] = colour_truth;
  if (summary.tabulated) {
    truth_json["generator"]["material_no_data"] = {{"policy", SynthNoDataName(options.no_data)},
                                                   {"table_cells_without_data", summary.table_cells_without_data},
                                                   {"pixels", summary.no_data_pixels},
                                                   {"photos_masked", summary.masked_photos}};
  }
  WriteJsonFile((fs::path(directory.temporary_path()) / "truth.json").string(), truth_json);
  directory.Commit();
  summary.photos = options.rig.num_photos + int(options.rig.extra_camera_positions.size());
  summary.saturated_pixels = saturated;
  summary.total_s = timer.ElapsedSeconds();
  summary.success = true;
  return summary;
}
}  // namespace

SynthSummary WriteSyntheticSession(const SynthOptions& options, const BrdfModel& material,
                                   const std::string& material_name, const std::string& out_dir, bool overwrite) {
  return WriteSession(options, SurfaceMaterial{&material, nullptr}, material_name, out_dir, overwrite);
}

SynthSummary WriteSyntheticSession(const SynthOptions& options, const MaterialMap& map, const std::string& map_name,
                                   const std::string& out_dir, bool overwrite) {
  for (size_t k = 0; k < map.NumMaterials(); ++k) {
    const auto* table = dynamic_cast<const MerlBrdf*>(&map.Material(k));
    if (table && table->cells_without_data() > 0) {
      ThrowError(map_name + ": /materials/" + std::to_string(k),
                 "\"" + map.Name(k) + "\" is a MERL table with " + std::to_string(table->cells_without_data()) +
                     " cells without data; a material map has no mask for them (use a complete table)");
    }
  }
  return WriteSession(options, SurfaceMaterial{nullptr, &map}, map_name, out_dir, overwrite);
}

}  // namespace ibrdf
