#include "derender/derenderer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <type_traits>
#include <variant>

#include <tbb/blocked_range.h>
#include <tbb/concurrent_queue.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/huge_pages.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/sample_file.h"
#include "derender/analytic_sample.h"
#include "derender/colour_correction.h"
#include "derender/mesh_sample.h"
#include "radiometry/photo_mask.h"
#include "radiometry/radiance_image.h"
#include "scan/convexity.h"
#include "scan/mesh_file.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

// Rejection reasons in RejectionReasons() order; each pixel counts once, under the first that applies.
// The per-pixel kernel tests all but the last, kColourUnmeasured, which the colour correction counts
// on the accepted samples (Derender).
enum Reason {
  kOff,
  kMasked,
  kMixed,
  kTarget,
  kLowQuality,
  kBackfacing,
  kUnlit,
  kGrazingE,
  kGrazingI,
  kShadowed,
  kShadowEdge,
  kNonFinite,
  kSaturated,
  kBelow,
  kColourUnmeasured,
  kNumReasons
};
using ReasonCounts = std::array<uint64_t, kNumReasons>;

void AddCounts(const ReasonCounts& counts, RejectionCounts* rejected) {
  const auto& reasons = RejectionReasons();
  for (int r = 0; r < kNumReasons; ++r) (*rejected)[reasons[r].first] += counts[r];
}

// The pixel box [x0, x1) x [y0, y1) that holds the projection of the sample's bounding sphere in one
// photo, with a 2-pixel margin; the whole image where the cone around the sphere is too wide to
// project (or holds the camera). Pixels outside it cannot see the sample.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool Empty() const { return x1 <= x0 || y1 <= y0; }
};

PixelBox SampleBox(const Camera& camera, const Rigid3d& camera_from_world, const SampleSurface& sample) {
  const PixelBox whole{0, 0, camera.width, camera.height};
  const Eigen::Vector3d c = camera_from_world * sample.BoundingCenter();
  const double distance = c.norm();
  const double radius = sample.BoundingRadius();
  if (!(distance > 1.5 * radius)) return whole;
  const Eigen::Vector3d axis = c / distance;
  const double sin_alpha = radius / distance, cos_alpha = std::sqrt(1.0 - sin_alpha * sin_alpha);
  // Entirely behind the camera: nothing to see.
  if (axis.z() < -sin_alpha) return PixelBox{};
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300;
  constexpr int kPoints = 64;
  for (int k = 0; k < kPoints; ++k) {
    const double angle = 2.0 * M_PI * k / kPoints;
    const Eigen::Vector3d d = cos_alpha * axis + sin_alpha * (std::cos(angle) * u + std::sin(angle) * v);
    if (!(d.z() > 0.1)) return whole;  // near or behind the image plane's horizon: do not cull
    const Eigen::Vector2d p = camera.ImageFromCamera(d);
    if (!p.allFinite()) return whole;
    x_min = std::min(x_min, p.x());
    x_max = std::max(x_max, p.x());
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
  }
  // The 64-gon's chords fall short of the curve by under 0.002 of its radius; 2 pixels cover that.
  PixelBox box;
  box.x0 = std::clamp(static_cast<int>(std::floor(x_min)) - 2, 0, camera.width);
  box.x1 = std::clamp(static_cast<int>(std::ceil(x_max)) + 2, 0, camera.width);
  box.y0 = std::clamp(static_cast<int>(std::floor(y_min)) - 2, 0, camera.height);
  box.y1 = std::clamp(static_cast<int>(std::ceil(y_max)) + 2, 0, camera.height);
  return box;
}

// PixelRays (derenderer.h) for the pixels inside `box` only; the others are left unset (Eigen does
// not initialize them, so their pages are never touched).
std::vector<Eigen::Vector2f> PixelRaysInBox(const Camera& camera, const PixelBox& box) {
  std::vector<Eigen::Vector2f> rays;
  ReserveWithHugePages(&rays, size_t(camera.width) * camera.height);
  rays.resize(size_t(camera.width) * camera.height);
  if (box.Empty()) return rays;
  tbb::parallel_for(tbb::blocked_range<int>(box.y0, box.y1), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = box.x0; x < box.x1; ++x) {
        rays[size_t(y) * camera.width + x] = camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5)).cast<float>();
      }
    }
  });
  return rays;
}

// PixelCornerRays (derenderer.h) for the corners inside `box` (corner coordinates, [x0, x1) x [y0, y1)
// of the (width + 1) x (height + 1) grid) only; the others are left unset.
std::vector<Eigen::Vector2f> PixelCornerRaysInBox(const Camera& camera, const PixelBox& box) {
  const int columns = camera.width + 1;
  std::vector<Eigen::Vector2f> rays;
  ReserveWithHugePages(&rays, size_t(columns) * (camera.height + 1));
  rays.resize(size_t(columns) * (camera.height + 1));
  if (box.Empty()) return rays;
  tbb::parallel_for(tbb::blocked_range<int>(box.y0, box.y1), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = box.x0; x < box.x1; ++x) {
        rays[size_t(y) * columns + x] = camera.CamPlaneFromImage(Eigen::Vector2d(x, y)).cast<float>();
      }
    }
  });
  return rays;
}

// The radiometric tests of a pixel (per-channel flags from radiance_image.h): kNumReasons when any
// channel is measured (the sample keeps a per-channel `valid` flag), else the first reason in
// RejectionReasons() order that a channel has.
inline Reason RadiometricReason(const uint8_t* channel_flags) {
  if (channel_flags[0] == 0 || channel_flags[1] == 0 || channel_flags[2] == 0) return kNumReasons;
  const uint8_t any = channel_flags[0] | channel_flags[1] | channel_flags[2];
  if (any & kPixelNonFinite) return kNonFinite;
  if (any & kPixelSaturated) return kSaturated;
  return kBelow;
}

// theta_h, the angle between the normal and the half vector of wi and wo (world directions), radians.
inline double HalfAngle(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d h = (wi + wo).normalized();
  return std::acos(std::clamp(h.dot(normal), -1.0, 1.0));
}

// Whether the photos' masks exclude pixel (x, y).
inline bool Masked(const RadianceWindow& image, int x, int y) {
  return !image.mask.empty() && !image.mask[size_t(y) * image.width() + x];
}

// f = L / E per channel, in the local frame of `normal`.
inline BrdfSample MakeSample(const PixelRadiance& pixel, const Eigen::Vector3d& normal, const Incidence& incidence,
                             const Eigen::Vector3d& wo_world, size_t photo_index, int x, int y) {
  const LocalFrame frame = LocalFrame::FromNormal(normal);
  const Eigen::Vector3d wi = frame.ToLocal(incidence.wi);
  const Eigen::Vector3d wo = frame.ToLocal(wo_world);
  const IsotropicAngles angles = ToIsotropic(wi, wo);
  BrdfSample s;
  for (int c = 0; c < 3; ++c) {
    s.wi[c] = static_cast<float>(wi[c]);
    s.wo[c] = static_cast<float>(wo[c]);
    const double irradiance = incidence.irradiance[c];
    const bool valid = pixel.channel_flags[c] == 0;
    // A channel not measured keeps its (clipped or noisy) value, at least 0, with sigma 0 and valid 0.
    s.brdf[c] = static_cast<float>(std::max(0.0, pixel.radiance[c] / irradiance));
    s.sigma[c] = valid ? static_cast<float>(pixel.sigma[c] / irradiance) : 0.0f;
    s.valid[c] = valid ? 1 : 0;
  }
  s.exposures = pixel.exposures;
  s.theta_i = static_cast<float>(angles.theta_i);
  s.theta_e = static_cast<float>(angles.theta_e);
  s.delta_phi = static_cast<float>(angles.delta_phi);
  s.image = static_cast<uint32_t>(photo_index);
  s.pixel[0] = static_cast<uint32_t>(x);
  s.pixel[1] = static_cast<uint32_t>(y);
  return s;
}

uint64_t PixelsPerImage(const Camera& camera, int stride) {
  return uint64_t((camera.width + stride - 1) / stride) * uint64_t((camera.height + stride - 1) / stride);
}

// One photo as the per-pixel kernel sees it: its pose, light and grazing limits, and the pixels traced
// (those of its sample box on the stride's grid; the others cannot see the sample).
struct PhotoView {
  PhotoView(const Session& session, size_t photo_index, const DerenderOptions& options, const SampleSurface& sample)
      : light(session.PhotoLight(photo_index)), stride(options.pixel_stride) {
    const Rigid3d& camera_from_world = *session.photos[photo_index].camera_from_world;
    const Rigid3d world_from_camera = camera_from_world.Inverse();
    world_from_camera_rotation = world_from_camera.rotation.toRotationMatrix();
    camera_center = world_from_camera.translation;
    cos_max_i = std::cos(options.max_theta_i_deg * kDegree);
    cos_max_e = std::cos(options.max_theta_e_deg * kDegree);
    box = SampleBox(session.camera, camera_from_world, sample);
    x_start = (box.x0 + stride - 1) / stride * stride;
    y_start = (box.y0 + stride - 1) / stride * stride;
    columns = box.x1 > x_start ? (box.x1 - x_start + stride - 1) / stride : 0;
    rows = box.y1 > y_start && columns > 0 ? (box.y1 - y_start + stride - 1) / stride : 0;
  }
  // The unit world direction of the ray through the undistorted image-plane point `xy`.
  Eigen::Vector3d Direction(const Eigen::Vector2f& xy) const {
    return (world_from_camera_rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
  }

  const Light& light;
  int stride = 1;
  Eigen::Matrix3d world_from_camera_rotation;
  Eigen::Vector3d camera_center;
  double cos_max_i = 0.0, cos_max_e = 0.0;  // cosines of the grazing limits
  PixelBox box;                             // the pixels that can see the sample
  int x_start = 0, y_start = 0;             // the box's first column and row on the stride's grid
  int columns = 0, rows = 0;                // pixels traced per row, rows traced (0 x 0 when none)
};

// What the kernel counts per block of rows.
struct BlockStats {
  ReasonCounts counts{};
  ExposureTally exposure;
  uint64_t shadow_rays = 0;
  uint64_t shadow_tests_skipped = 0;
};

// Everything the mesh path prepares once per session.
struct MeshPath {
  std::unique_ptr<MeshSample> mesh;
  std::unique_ptr<QuadOccluders> occluders;  // null without reference markers
  bool shadow_rays = false;
  std::string visibility_reason;
  std::vector<Eigen::Vector2f> corner_rays;  // PixelCornerRays, when mixed pixels are masked
  double half_diagonal = 0.0;                // a pixel's half-diagonal, radians (image centre)
};

// Whether the light reaches `point` (on the surface, normal `normal`, fit residual `fit_rms_m`):
// kNumReasons if it does, kShadowed or kShadowEdge if not.
Reason ShadowTest(const MeshSample& mesh, const Light& light, const Incidence& incidence, const Eigen::Vector3d& point,
                  const Eigen::Vector3d& normal, float fit_rms_m, const DerenderOptions& options, uint64_t* rays) {
  const double offset = 4.0 * mesh.Epsilon() + options.shadow_ray_offset_fit_rms * std::max(0.0f, fit_rms_m);
  const Eigen::Vector3d from = point + offset * normal;
  double distance = 0.0;
  Eigen::Vector3d to = Eigen::Vector3d::Zero();
  switch (light.kind) {
    case Light::Kind::kPoint:
      distance = (light.position - from).norm();
      to = light.position;
      break;
    case Light::Kind::kDirectional:
      distance = 4.0 * mesh.BoundingRadius();
      to = from + distance * incidence.wi;
      break;
  }
  ++*rays;
  if (mesh.Occluded(from, to)) return kShadowed;
  if (options.shadow_edge_rays > 0 && options.shadow_edge_deg > 0.0) {
    const double radius = distance * std::tan(options.shadow_edge_deg * kDegree);
    const Eigen::Vector3d u = incidence.wi.unitOrthogonal(), v = incidence.wi.cross(u);
    for (int k = 0; k < options.shadow_edge_rays; ++k) {
      const double angle = 2.0 * M_PI * k / options.shadow_edge_rays;
      ++*rays;
      if (mesh.Occluded(from, to + radius * (std::cos(angle) * u + std::sin(angle) * v))) return kShadowEdge;
    }
  }
  return kNumReasons;
}

// The sample geometries of the per-pixel kernel. Each is a per-photo type whose nested Tracer (made
// once per block of rows, on the block's thread) gives the kernel, all inlined into its pixel loop:
//   bool BeginRow(int y): prepares row y; false when no pixel of the row hits the sample;
//   const SurfaceHit* Trace(int i, int x, Eigen::Vector3d* direction): pixel i (column x) of the row:
//     its ray's unit world direction and its hit, or null for a miss;
//   Reason BeforeLight(int x, const SurfaceHit&, const Eigen::Vector3d& direction): the geometry's own
//     rejections ahead of the light's (mesh: mixed pixels, markers in front, poor normals, back faces);
//   Reason AfterGrazing(const SurfaceHit&, const Incidence&, BlockStats*): its rejections after the
//     grazing tests (mesh: shadows).
// kNumReasons: none applies.

// A sphere or cylinder (Shape: the concrete type, so its Intersect is inlined), one ray at a time.
template <class Shape>
struct AnalyticPhoto {
  const Shape& shape;
  const std::vector<Eigen::Vector2f>& rays;
  int width;

  class Tracer {
   public:
    Tracer(const AnalyticPhoto& photo, const PhotoView& view) : photo_(photo), view_(view) {}
    bool BeginRow(int y) {
      y_ = y;
      return true;
    }
    const SurfaceHit* Trace(int, int x, Eigen::Vector3d* direction) {
      *direction = view_.Direction(photo_.rays[size_t(y_) * photo_.width + x]);
      return photo_.shape.Intersect(view_.camera_center, *direction, &hit_) ? &hit_ : nullptr;
    }
    Reason BeforeLight(int, const SurfaceHit&, const Eigen::Vector3d&) const { return kNumReasons; }
    Reason AfterGrazing(const SurfaceHit&, const Incidence&, BlockStats*) const { return kNumReasons; }

   private:
    const AnalyticPhoto& photo_;
    const PhotoView& view_;
    int y_ = 0;
    SurfaceHit hit_;  // reused: Intersect sets every field it reports
  };
};

// The scanned mesh: each row's rays handed to Embree together, the mixed-pixel test on the depths of
// the pixel corners (the rows inside a block share them), the marker, normal-quality and back-face
// masks, and (visibility on) shadow rays.
class MeshPhoto {
 public:
  MeshPhoto(const MeshPath& path, const PhotoView& view, const std::vector<Eigen::Vector2f>& rays, int width,
            const DerenderOptions& options)
      : path_(path), rays_(rays), width_(width), options_(options),
        mask_mixed_(options.mask_mixed_pixels && !path.corner_rays.empty()) {
    // Corner columns used by the row's pixels: x and x + 1 of each.
    for (int i = 0; i < view.columns; ++i) {
      const int x = view.x_start + i * view.stride;
      if (corner_xs_.empty() || corner_xs_.back() != x) corner_xs_.push_back(x);
      corner_xs_.push_back(x + 1);
    }
    corner_index_.assign(size_t(width) + 1, -1);
    for (size_t k = 0; k < corner_xs_.size(); ++k) corner_index_[corner_xs_[k]] = int(k);
  }

  class Tracer {
   public:
    Tracer(const MeshPhoto& photo, const PhotoView& view)
        : photo_(photo), view_(view), mesh_(*photo.path_.mesh), nx_(size_t(view.columns)),
          directions_(nx_), hits_(nx_), found_(new bool[nx_]), corner_directions_(photo.corner_xs_.size()),
          top_(photo.corner_xs_.size()), bottom_(photo.corner_xs_.size()) {}

    bool BeginRow(int y) {
      for (size_t i = 0; i < nx_; ++i) {
        const Eigen::Vector2f& xy = photo_.rays_[size_t(y) * photo_.width_ + view_.x_start + int(i) * view_.stride];
        directions_[i] = view_.Direction(xy);
      }
      mesh_.IntersectBatch(view_.camera_center, directions_.data(), nx_, hits_.data(), found_.get());
      bool any_hit = false;
      for (size_t i = 0; i < nx_; ++i) any_hit |= found_[i];
      if (!any_hit) return false;
      if (photo_.mask_mixed_) {
        if (bottom_row_ == y) {
          top_.swap(bottom_);
        } else {
          TraceCorners(y, &top_);
        }
        TraceCorners(y + 1, &bottom_);
        bottom_row_ = y + 1;
      }
      return true;
    }

    const SurfaceHit* Trace(int i, int, Eigen::Vector3d* direction) const {
      *direction = directions_[i];
      return found_[i] ? &hits_[i] : nullptr;
    }

    Reason BeforeLight(int x, const SurfaceHit& hit, const Eigen::Vector3d& direction) const {
      const DerenderOptions& options = photo_.options_;
      if (photo_.mask_mixed_) {
        const double tolerance = options.mixed_pixel_depth_factor * hit.t * photo_.path_.half_diagonal;
        const int k0 = photo_.corner_index_[x], k1 = photo_.corner_index_[x + 1];
        const double corners[4] = {top_[k0], top_[k1], bottom_[k0], bottom_[k1]};
        bool mixed = false;
        for (double t : corners) mixed |= !(std::abs(t - hit.t) <= tolerance);  // NaN (a miss) is mixed
        if (mixed) return kMixed;
      }
      if (photo_.path_.occluders && photo_.path_.occluders->Blocks(view_.camera_center, direction, hit.t)) {
        return kTarget;
      }
      const bool no_fit = hit.fit_neighbours >= 0 && hit.fit_neighbours < options.min_fit_neighbours;
      const bool poor_fit = options.max_normal_fit_rms_m > 0.0 && hit.fit_rms_m > options.max_normal_fit_rms_m;
      if (hit.normal.isZero(0.0) || no_fit || poor_fit) return kLowQuality;
      const Eigen::Vector3d wo_world = -direction;
      if (!(wo_world.dot(hit.normal) > 0.0) || !(wo_world.dot(hit.geometric_normal) > 0.0)) return kBackfacing;
      return kNumReasons;
    }

    Reason AfterGrazing(const SurfaceHit& hit, const Incidence& incidence, BlockStats* stats) const {
      if (!photo_.path_.shadow_rays) {
        ++stats->shadow_tests_skipped;
        return kNumReasons;
      }
      return ShadowTest(mesh_, view_.light, incidence, hit.point, hit.normal, hit.fit_rms_m, photo_.options_,
                        &stats->shadow_rays);
    }

   private:
    // The corner distances (NaN: the corner ray misses) of corner row `row`.
    void TraceCorners(int row, std::vector<double>* depths) {
      const size_t nc = photo_.corner_xs_.size();
      for (size_t k = 0; k < nc; ++k) {
        const Eigen::Vector2f& xy = photo_.path_.corner_rays[size_t(row) * (photo_.width_ + 1) + photo_.corner_xs_[k]];
        corner_directions_[k] = view_.Direction(xy);
      }
      mesh_.DepthBatch(view_.camera_center, corner_directions_.data(), nc, depths->data());
    }

    const MeshPhoto& photo_;
    const PhotoView& view_;
    const MeshSample& mesh_;
    const size_t nx_;
    std::vector<Eigen::Vector3d> directions_;
    std::vector<SurfaceHit> hits_;
    std::unique_ptr<bool[]> found_;
    std::vector<Eigen::Vector3d> corner_directions_;
    // Corner distances of the rows above and below the pixel row.
    std::vector<double> top_, bottom_;
    int bottom_row_ = -1;
  };

 private:
  const MeshPath& path_;
  const std::vector<Eigen::Vector2f>& rays_;
  const int width_;
  const DerenderOptions& options_;
  const bool mask_mixed_;
  std::vector<int> corner_xs_;
  std::vector<int> corner_index_;  // per corner column of the image: its index in corner_xs_, or -1
};

// The per-pixel kernel, for every geometry (Geometry: AnalyticPhoto or MeshPhoto), on rows
// [row_begin, row_end) of the photo's traced rows: appends the accepted samples in row-major order to
// `samples`, counts the rejections, under the first reason in RejectionReasons() order that applies,
// and tallies the pixels that reach the radiometric tests. The hot loop of the stage.
template <class Geometry>
void DerenderRows(const Geometry& geometry, const PhotoView& photo_view, const RadianceWindow& image,
                  size_t photo_index, int row_begin, int row_end, std::vector<BrdfSample>* samples,
                  BlockStats* stats) {
  const PhotoView view = photo_view;  // a local copy: its fields stay in registers across the stores below
  typename Geometry::Tracer tracer(geometry, view);
  ReasonCounts counts{};
  for (int r = row_begin; r < row_end; ++r) {
    const int y = view.y_start + r * view.stride;
    if (!tracer.BeginRow(y)) {
      counts[kOff] += view.columns;
      continue;
    }
    for (int i = 0; i < view.columns; ++i) {
      const int x = view.x_start + i * view.stride;
      Eigen::Vector3d direction;
      const SurfaceHit* hit = tracer.Trace(i, x, &direction);
      if (!hit) {
        ++counts[kOff];
        continue;
      }
      if (Masked(image, x, y)) {
        ++counts[kMasked];
        continue;
      }
      const Reason surface = tracer.BeforeLight(x, *hit, direction);
      if (surface != kNumReasons) {
        ++counts[surface];
        continue;
      }
      const Incidence incidence = IncidenceAt(view.light, hit->point, hit->normal);
      if (!incidence.lit) {
        ++counts[kUnlit];
        continue;
      }
      const Eigen::Vector3d wo_world = -direction;
      const double cos_e = wo_world.dot(hit->normal);
      if (!(cos_e >= view.cos_max_e)) {
        ++counts[kGrazingE];
        continue;
      }
      if (!(incidence.cos_theta >= view.cos_max_i)) {
        ++counts[kGrazingI];
        continue;
      }
      const Reason light = tracer.AfterGrazing(*hit, incidence, stats);
      if (light != kNumReasons) {
        ++counts[light];
        continue;
      }
      PixelRadiance pixel;
      image.At(x, y, &pixel);
      stats->exposure.Add(HalfAngle(incidence.wi, wo_world, hit->normal), pixel.channel_flags);
      const Reason radiometric = RadiometricReason(pixel.channel_flags);
      if (radiometric != kNumReasons) {
        ++counts[radiometric];
        continue;
      }
      samples->push_back(MakeSample(pixel, hit->normal, incidence, wo_world, photo_index, x, y));
    }
  }
  for (int r = 0; r < kNumReasons; ++r) stats->counts[r] += counts[r];
}

// One photo's traced rows in blocks (each into its own buffer of `out`, across threads when
// `parallel`), the blocks' counts merged into `out`. The mesh's first row of a block traces its top
// corners anew (the rows inside a block share them), so blocks are long enough to make that cheap and
// many enough (tens per photo) to balance the threads.
template <class Geometry>
void DerenderBlocks(const Geometry& geometry, const PhotoView& view, const RadianceWindow& image, size_t photo_index,
                    uint64_t examined, bool parallel, PhotoSamples* out) {
  constexpr int kRowsPerBlock = 16;
  const size_t blocks = size_t(view.rows + kRowsPerBlock - 1) / kRowsPerBlock;
  for (std::vector<BrdfSample>& block : out->blocks) block.clear();
  if (out->blocks.size() < blocks) out->blocks.resize(blocks);
  std::vector<BlockStats> block_stats(blocks);
  const auto derender_block = [&](size_t b) {
    const int first = int(b) * kRowsPerBlock, last = std::min(view.rows, first + kRowsPerBlock);
    std::vector<BrdfSample>& samples = out->blocks[b];
    // Room for every traced pixel: no regrowth copies (each costs more than the pixels' work).
    ReserveWithHugePages(&samples, size_t(view.columns) * size_t(last - first));
    DerenderRows(geometry, view, image, photo_index, first, last, &samples, &block_stats[b]);
  };
  if (parallel) {
    tbb::parallel_for(size_t(0), blocks, derender_block);
  } else {
    for (size_t b = 0; b < blocks; ++b) derender_block(b);
  }
  // Only the pixels that can see the sample are traced; the others are off the sample by construction.
  ReasonCounts counts{};
  counts[kOff] = examined - uint64_t(view.rows) * uint64_t(view.columns);
  out->rejected.clear();
  out->exposure = ExposureTally();
  out->shadow_rays = 0;
  out->shadow_tests_skipped = 0;
  for (const BlockStats& stats : block_stats) {
    for (int r = 0; r < kNumReasons; ++r) counts[r] += stats.counts[r];
    out->exposure.Merge(stats.exposure);
    out->shadow_rays += stats.shadow_rays;
    out->shadow_tests_skipped += stats.shadow_tests_skipped;
  }
  AddCounts(counts, &out->rejected);
}

// Whether the scan's convexity report asks for shadow rays: from the scan stage's sidecar
// (<mesh>.json, convexity.needs_shadow_rays) when it describes this mesh (its mesh name, point and
// face counts match, and the mesh is not newer than it), else computed here (CGAL's hull of the
// points, about a second for 400 k faces) and the reason said.
bool NeedsShadowRays(const std::string& mesh_path, const ScanMesh& mesh, std::string* reason) {
  const std::string sidecar = ScanSidecarPath(mesh_path);
  std::string stale;
  if (fs::is_regular_file(sidecar)) {
    const nlohmann::json json = ReadJsonFile(sidecar);
    const auto convexity = json.find("convexity");
    const auto needs =
        convexity != json.end() && convexity->is_object() ? convexity->find("needs_shadow_rays") : json.end();
    if (convexity == json.end() || !convexity->is_object() || needs == convexity->end() || !needs->is_boolean()) {
      ThrowError(sidecar, "expected convexity.needs_shadow_rays (a boolean), as `ibrdf scan` writes it");
    }
    const auto count = [&](const char* key) {
      const auto it = json.find(key);
      return it != json.end() && it->is_number_unsigned() ? it->get<uint64_t>() : uint64_t(-1);
    };
    const auto name = json.find("mesh");
    std::error_code error;
    if (name != json.end() && name->is_string() && *name != fs::path(mesh_path).filename().string()) {
      stale = "it describes " + name->get<std::string>();
    } else if (count("points") != mesh.points.size() || count("faces") != mesh.faces.size()) {
      stale = "its point or face count differs from the mesh's";
    } else if (fs::last_write_time(mesh_path, error) > fs::last_write_time(sidecar, error) || error) {
      stale = "the mesh is newer than it";
    } else {
      *reason = std::string("auto: the scan's convexity report (") + sidecar + ") says " +
                (needs->get<bool>() ? "not convex" : "convex");
      return needs->get<bool>();
    }
  }
  const ConvexityReport report = ReportConvexity(mesh, ConvexityOptions());
  *reason = "auto: " + report.BriefReport() +
            (stale.empty() ? " (computed here: no scan sidecar " + sidecar + ")"
                           : " (computed here: the scan sidecar " + sidecar + " is stale: " + stale + ")");
  return report.needs_shadow_rays;
}

MeshPath PrepareMeshPath(const Session& session, const DerenderOptions& options) {
  MeshPath path;
  const std::string file = ResolvePath(session.directory, session.sample.mesh_file);
  const std::string where = session.manifest_path + ": /sample/file";
  if (!fs::exists(file)) {
    ThrowError(where, "the mesh " + file + " does not exist (`ibrdf scan` writes it from the scan_inputs)");
  }
  if (!fs::is_regular_file(file)) ThrowError(where, file + " is not a file");
  const ScanMesh mesh = ReadTriangleMeshFile(file);
  const Visibility visibility = options.visibility.value_or(session.sample.visibility);
  const std::string source = options.visibility ? "option" : "session";
  // The ray-tracing scene and (visibility auto) the convexity verdict at the same time: on a 400 k-face
  // mesh without a scan sidecar the hull alone takes seconds.
  bool auto_shadow_rays = false;
  tbb::parallel_invoke([&] { path.mesh = std::make_unique<MeshSample>(mesh, session.sample.world_from_mesh, file); },
                       [&] {
                         if (visibility == Visibility::kAuto)
                           auto_shadow_rays = NeedsShadowRays(file, mesh, &path.visibility_reason);
                       });
  switch (visibility) {
    case Visibility::kOn:
      path.shadow_rays = true;
      path.visibility_reason = "on (" + source + ")";
      break;
    case Visibility::kOff:
      path.shadow_rays = false;
      path.visibility_reason = "off (" + source + ")";
      break;
    case Visibility::kAuto:
      path.shadow_rays = auto_shadow_rays;
      break;
  }
  if (session.targets) {
    std::vector<std::array<Eigen::Vector3d, 4>> quads;
    for (const TargetSpec& target : session.targets->reference) quads.push_back(target.corners);
    if (!quads.empty()) path.occluders = std::make_unique<QuadOccluders>(quads);
  }
  if (options.mask_mixed_pixels) {
    // Corner rays only where a photo's sample box reads them (its pixels' corners x .. x + 1, y .. y + 1).
    PixelBox corners{session.camera.width + 1, session.camera.height + 1, 0, 0};
    for (const PhotoSpec& photo : session.photos) {
      if (photo.role == PhotoRole::kTargets || !photo.camera_from_world) continue;
      const PixelBox box = SampleBox(session.camera, *photo.camera_from_world, *path.mesh);
      if (box.Empty()) continue;
      corners.x0 = std::min(corners.x0, box.x0);
      corners.y0 = std::min(corners.y0, box.y0);
      corners.x1 = std::max(corners.x1, box.x1 + 1);
      corners.y1 = std::max(corners.y1, box.y1 + 1);
    }
    path.corner_rays = PixelCornerRaysInBox(session.camera, corners);
    path.half_diagonal = 0.5 * std::hypot(1.0 / session.camera.FocalX(), 1.0 / session.camera.FocalY());
  }
  Log(1, "mesh " + file + ": " + std::to_string(path.mesh->NumPoints()) + " points, " +
             std::to_string(path.mesh->NumFaces()) + " faces" +
             (path.mesh->HasFitQuality() ? "" : " (no fit quality: normals taken as they are)") + "; shadow rays " +
             (path.shadow_rays ? "on" : "off") + ": " + path.visibility_reason);
  return path;
}

// The stage's set-up of one session (DerenderSetup), made before the first photo is decoded, in the
// order its errors are reported: options, the sample's geometry, the photos' poses and lights, the
// sample boxes, the photo files, the radiometric chain, the shared masks.
struct Stage {
  Stage(const Session& session, const DerenderOptions& options);
  // The sample's surface (for the checks and the sample boxes; the kernel takes the concrete type).
  const SampleSurface& Surface() const;

  const Session& session;
  const DerenderOptions options;
  Timer timer;  // the stage's wall clock (the summary's total_s), from the end of the mesh's set-up
  std::optional<AnalyticShape> analytic;  // a sphere or a cylinder
  std::unique_ptr<MeshPath> mesh;         // a scanned mesh
  double mesh_setup_s = 0.0;              // mesh: reading it, the ray-tracing scene, the convexity verdict
  std::vector<std::vector<size_t>> groups;  // the photos derendered (ExposureGroups)
  std::vector<PixelBox> boxes;              // per group: the pixels that can see the sample
  // The rays of the pixels some group's box holds (the kernel reads no others): undistorting every
  // pixel of the camera costs more than the geometry of the sample's pixels.
  std::vector<Eigen::Vector2f> rays;
  std::unique_ptr<RadianceReader> reader;
  // Per group, a mask that several groups use (the session's default mask, usually), decoded once;
  // null: the group's masks are read as it is worked on.
  std::vector<std::shared_ptr<const std::vector<uint8_t>>> shared_masks;
};

// Everything about the photos that can be checked before decoding, so a bad session fails at once.
void CheckPhotoPoses(const Session& session, const SampleSurface& sample) {
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    const std::string where = session.manifest_path + ": /photos/" + std::to_string(i);
    if (!photo.camera_from_world) {
      ThrowError(where, "photo " + photo.file + " has no camera_from_world pose (run `ibrdf align` first)");
    }
    if (sample.Contains(photo.camera_from_world->Inverse().translation)) {
      ThrowError(where, "the camera centre is inside the sample");
    }
    if (photo.role == PhotoRole::kMeasurement && !session.PhotoLight(i).placement_known) {
      ThrowError(where, "photo " + photo.file + " was taken under " + LightLabel(session.PhotoLight(i)) +
                            ", whose position is unknown (run `ibrdf align`, which finds it from the light's "
                            "markers, or state it)");
    }
    if (photo.role == PhotoRole::kMeasurement && !session.PhotoLight(i).has_intensity) {
      ThrowError(where, "photo " + photo.file + " was taken under " + LightLabel(session.PhotoLight(i)) +
                            ", which has no intensity and no calibration measures it (give the light's "
                            "\"intensity\", or white-reference photos under it)");
    }
  }
}

// The masks that more than one group uses, decoded once (per group; null where none is shared).
std::vector<std::shared_ptr<const std::vector<uint8_t>>> SharedMasks(const Session& session,
                                                                     const std::vector<std::vector<size_t>>& groups) {
  std::vector<std::shared_ptr<const std::vector<uint8_t>>> shared(groups.size());
  std::map<std::vector<std::string>, std::vector<size_t>> groups_by_masks;
  for (size_t g = 0; g < groups.size(); ++g) {
    std::vector<std::string> paths;
    for (size_t i : groups[g]) paths.push_back(session.PhotoMaskPath(i));
    groups_by_masks[paths].push_back(g);
  }
  for (const auto& [paths, users] : groups_by_masks) {
    bool any_mask = false;
    for (const std::string& path : paths) any_mask = any_mask || !path.empty();
    if (!any_mask || users.size() < 2) continue;
    const auto mask = std::make_shared<const std::vector<uint8_t>>(ReadGroupMask(session, groups[users.front()]));
    for (size_t g : users) shared[g] = mask;
  }
  return shared;
}

Stage::Stage(const Session& session_in, const DerenderOptions& options_in)
    : session(session_in), options(options_in) {
  std::string why;
  if (!options.Check(&why)) ThrowError("derender options", why);
  switch (session.sample.kind) {
    case SampleSpec::Kind::kSphere:
    case SampleSpec::Kind::kCylinder:
      analytic = MakeAnalyticShape(session.sample);
      break;
    case SampleSpec::Kind::kMesh: {
      const Timer setup;
      mesh = std::make_unique<MeshPath>(PrepareMeshPath(session, options));
      mesh_setup_s = setup.ElapsedSeconds();
      char seconds[32];
      std::snprintf(seconds, sizeof(seconds), "%.2f s", mesh_setup_s);
      Log(1, std::string("mesh set-up (read, ray-tracing scene, convexity): ") + seconds);
      timer.Restart();
      break;
    }
  }
  CheckPhotoPoses(session, Surface());
  groups = ExposureGroups(session);
  bool any_sees = groups.empty();
  for (const auto& group : groups) {
    boxes.push_back(SampleBox(session.camera, *session.photos[group.front()].camera_from_world, Surface()));
    any_sees |= !boxes.back().Empty();
  }
  if (!any_sees) {
    ThrowError(session.manifest_path,
               "no photo sees the sample: its bounding sphere projects outside every "
               "measurement photo (check the sample's position" +
                   std::string(mesh ? " and world_from_mesh" : "") + " and the poses)");
  }
  session.CheckPhotos();
  PixelBox ray_box{session.camera.width, session.camera.height, 0, 0};
  for (const PixelBox& box : boxes) {
    if (box.Empty()) continue;
    ray_box.x0 = std::min(ray_box.x0, box.x0);
    ray_box.y0 = std::min(ray_box.y0, box.y0);
    ray_box.x1 = std::max(ray_box.x1, box.x1);
    ray_box.y1 = std::max(ray_box.y1, box.y1);
  }
  rays = PixelRaysInBox(session.camera, ray_box);
  reader = std::make_unique<RadianceReader>(session);
  shared_masks = SharedMasks(session, groups);
}

const SampleSurface& Stage::Surface() const {
  if (mesh) return *mesh->mesh;
  return std::visit([](const auto& shape) -> const SampleSurface& { return shape; }, *analytic);
}

// DerenderSetup::ReadPhoto: each photo (exposure group) is linearized only inside the pixel box that
// can see the sample (the kernel traces nothing outside it).
void ReadStagePhoto(const Stage& stage, size_t group, RadianceWindow* image, double* decode_s) {
  const PixelBox& box = stage.boxes[group];
  std::vector<PhotoSpec> exposures;
  for (size_t i : stage.groups[group]) exposures.push_back(stage.session.photos[i]);
  stage.reader->PrepareWindow(exposures, stage.options.min_signal, PixelWindow{box.x0, box.y0, box.x1, box.y1}, image,
                              decode_s);
  if (stage.shared_masks[group]) {
    image->mask = *stage.shared_masks[group];
  } else {
    image->mask = ReadGroupMask(stage.session, stage.groups[group]);
  }
}

// DerenderSetup::DerenderPhoto: the kernel on the concrete geometry (a sphere's or a cylinder's
// Intersect inlined into the pixel loop, or the mesh's batches of rays).
void DerenderStagePhoto(const Stage& stage, size_t group, const RadianceWindow& image, bool parallel,
                        PhotoSamples* out) {
  const size_t photo_index = stage.groups[group].front();
  const PhotoView view(stage.session, photo_index, stage.options, stage.Surface());
  const uint64_t examined = PixelsPerImage(stage.session.camera, stage.options.pixel_stride);
  const int width = stage.session.camera.width;
  if (stage.mesh) {
    const MeshPhoto mesh(*stage.mesh, view, stage.rays, width, stage.options);
    DerenderBlocks(mesh, view, image, photo_index, examined, parallel, out);
    return;
  }
  std::visit(
      [&](const auto& shape) {
        const AnalyticPhoto<std::decay_t<decltype(shape)>> analytic{shape, stage.rays, width};
        DerenderBlocks(analytic, view, image, photo_index, examined, parallel, out);
      },
      *stage.analytic);
}

// The stage's summary after the last photo: totals, exposure advice, the mesh's figures and the
// check that some pixel saw the sample.
void FinishSummary(const Stage& stage, DerenderSummary* summary_ptr) {
  DerenderSummary& summary = *summary_ptr;
  const size_t measured = stage.groups.size();
  summary.photos = measured;
  summary.pixels_examined = PixelsPerImage(stage.session.camera, stage.options.pixel_stride) * measured;
  bool bracketed = false;
  for (const auto& group : stage.groups) bracketed = bracketed || group.size() > 1;
  summary.exposure_warnings = AdviseExposure(summary.exposure, stage.options.exposure_advice, bracketed);
  if (measured > 0 && summary.rejected["off_sample"] == summary.pixels_examined) {
    ThrowError(stage.session.manifest_path,
               "no photo sees the sample: every pixel's ray misses it (check the sample's "
               "position" +
                   std::string(stage.mesh ? " and world_from_mesh" : "") + " and the poses)");
  }
  if (stage.mesh) {
    summary.mesh_faces = stage.mesh->mesh->NumFaces();
    summary.shadow_rays_on = stage.mesh->shadow_rays;
    summary.visibility_reason = stage.mesh->visibility_reason;
    summary.mesh_setup_s = stage.mesh_setup_s;
    if (!stage.mesh->shadow_rays) {
      Log(1, "shadow rays skipped for " + std::to_string(summary.shadow_tests_skipped) + " pixels (visibility " +
                 stage.mesh->visibility_reason + ")");
    } else {
      Log(1, std::to_string(summary.shadow_rays) + " shadow rays traced");
    }
  }
  summary.total_s = stage.timer.ElapsedSeconds();
}

// Where RunStage sends the samples: each photo's blocks (their concatenation is the photo's samples),
// photo by photo in photo order. The blocks are the pipeline's buffers, valid until the sink returns.
using PhotoSink = std::function<void(const std::vector<std::vector<BrdfSample>>& blocks)>;

// Room for every pixel of every box: the most samples the stage can accept.
uint64_t MostSamples(const Stage& stage) {
  const int stride = stage.options.pixel_stride;
  uint64_t box_pixels = 0;
  for (const PixelBox& box : stage.boxes) {
    if (!box.Empty())
      box_pixels += uint64_t((box.x1 - box.x0 + stride - 1) / stride) * ((box.y1 - box.y0 + stride - 1) / stride);
  }
  return box_pixels;
}

// The stage's photos through a TBB pipeline that keeps a few photos in flight, so one is decoded while
// another's pixels are worked on; each token's buffers (decoded files, radiance window, samples) are
// reused from photo to photo, and the samples go to `sink` in photo order, byte-identical to a
// photo-by-photo loop. The memory is that of the tokens, whatever the number of photos. `colour`
// (SampleColourMatrices; empty: none) is applied to each photo's samples as they come, its counts
// added to `colour_counts`; the summary's channel counts and `accepted` are those after it.
DerenderSummary RunStage(const Stage& stage, const std::vector<Eigen::Matrix3d>& colour,
                         ColourCorrectionCounts* colour_counts, const PhotoSink& sink) {
  DerenderSummary summary;
  summary.sample = SampleKindName(stage.session.sample.kind);
  const size_t photos = stage.groups.size();
  struct PhotoWork {
    size_t group = 0;
    RadianceWindow image;  // the decoded exposures, merged pixel by pixel on demand
    PhotoSamples samples;
    double decode_s = 0.0;
    std::array<uint64_t, 3> channels_not_measured{};
    ColourCorrectionCounts colour;
  };
  // One photo in flight per thread and one more waiting its turn in the in-order merge: each token
  // holds full-frame buffers (tens of MB whose first touch costs page faults), so no more than that.
  const size_t tokens = size_t(std::max(2, tbb::this_task_arena::max_concurrency() + 1));
  std::vector<std::unique_ptr<PhotoWork>> work(tokens);
  tbb::concurrent_queue<PhotoWork*> idle;
  for (auto& w : work) {
    w = std::make_unique<PhotoWork>();
    idle.push(w.get());
  }
  ProgressBar progress("photos", photos);
  size_t next_group = 0;
  tbb::parallel_pipeline(
      tokens,
      tbb::make_filter<void,
                       PhotoWork*>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& control) -> PhotoWork* {
        if (next_group == photos) {
          control.stop();
          return nullptr;
        }
        PhotoWork* w = nullptr;
        IBRDF_CHECK(idle.try_pop(w)) << "no idle photo buffers";
        w->group = next_group++;
        return w;
      }) & tbb::make_filter<PhotoWork*, PhotoWork*>(tbb::filter_mode::parallel, [&](PhotoWork* w) {
        w->decode_s = 0.0;
        ReadStagePhoto(stage, w->group, &w->image, &w->decode_s);
        // A mesh photo's blocks, and those of the last two analytic photos, across threads (a thread
        // done with its photo then takes blocks of the other's, instead of waiting; a one-photo session
        // uses every thread); the other analytic photos one per thread.
        const bool parallel = stage.mesh || w->group + 2 >= photos;
        DerenderStagePhoto(stage, w->group, w->image, parallel, &w->samples);
        // Corrected and counted here, while the photo's samples are in cache (each sample is corrected
        // on its own, so photo by photo equals all at once).
        w->colour = ColourCorrectionCounts();
        w->channels_not_measured = {};
        for (std::vector<BrdfSample>& block : w->samples.blocks) {
          ApplyColourMatrices(stage.session, colour, &block, &w->colour);
          for (const BrdfSample& s : block) {
            for (int c = 0; c < 3; ++c) w->channels_not_measured[c] += s.valid[c] == 0;
          }
        }
        return w;
      }) & tbb::make_filter<PhotoWork*, void>(tbb::filter_mode::serial_in_order, [&](PhotoWork* w) {
        sink(w->samples.blocks);
        for (const std::vector<BrdfSample>& block : w->samples.blocks) summary.accepted += block.size();
        for (const auto& [reason, count] : w->samples.rejected) summary.rejected[reason] += count;
        summary.decode_s += w->decode_s;
        for (int c = 0; c < 3; ++c) {
          summary.channels_not_measured[c] += w->channels_not_measured[c];
          colour_counts->negative[c] += w->colour.negative[c];
        }
        colour_counts->dropped += w->colour.dropped;
        summary.shadow_rays += w->samples.shadow_rays;
        summary.shadow_tests_skipped += w->samples.shadow_tests_skipped;
        summary.exposure.Merge(w->samples.exposure);
        idle.push(w);
        progress.Add(1);
      }));
  progress.Finish();
  FinishSummary(stage, &summary);
  return summary;
}

// RunStage into memory.
DerenderResult RunStageInMemory(const Stage& stage, const std::vector<Eigen::Matrix3d>& colour,
                                ColourCorrectionCounts* colour_counts) {
  DerenderResult result;
  // The samples never regrow, and only the pages written are touched.
  ReserveWithHugePages(&result.samples, MostSamples(stage));
  result.summary = RunStage(stage, colour, colour_counts, [&](const std::vector<std::vector<BrdfSample>>& blocks) {
    for (const std::vector<BrdfSample>& block : blocks) {
      result.samples.insert(result.samples.end(), block.begin(), block.end());
    }
  });
  return result;
}

DerenderSummary& SummaryOf(DerenderResult& result) { return result.summary; }
DerenderSummary& SummaryOf(DerenderSummary& summary) { return summary; }

// Derender's checks and set-up, then the stage run by `run` (RunStage with the colour chart's matrices
// applied photo by photo), and the colour correction's figures in the summary.
template <class Run>
auto DerenderWith(const Session& session, const DerenderOptions& options, const Run& run) {
  std::string why;
  if (!options.Check(&why)) ThrowError("derender options", why);
  // The derenderer reads calibrated lights only: the white reference is a calibration of its own
  // (calibrate/white_reference_intensity.h), which writes the lights' intensities into the session.
  if (session.calibration && session.calibration->white_reference) {
    ThrowError(session.manifest_path + ": /calibration/white_reference",
               "the lights are not calibrated from the white reference yet: run `ibrdf lights white` on the "
               "session and derender the session it writes (`ibrdf run` does both)");
  }
  const Stage stage(session, options);
  // The colour chart's matrix, per sample by its photo's light (colour_correction.h), known before any
  // photo is decoded: a chart without a matrix fails at once.
  const std::vector<Eigen::Matrix3d> matrices = SampleColourMatrices(session);
  ColourCorrectionCounts colour;
  auto result = run(stage, matrices, &colour);
  DerenderSummary& summary = SummaryOf(result);
  summary.colour_matrices = matrices;
  if (!matrices.empty()) {
    Log(1, ColourCorrectionReport(session, matrices));
    summary.rejected["colour_unmeasured"] += colour.dropped;
    summary.colour_negative = colour.negative;
  }
  if (colour.dropped > 0) {
    Log(1, "warning: colour: " + std::to_string(colour.dropped) +
               " samples removed: after the colour matrix none of their channels is measured (each mixes an "
               "unmeasured camera channel or came out negative)");
  }
  return result;
}

}  // namespace

struct DerenderSetup::Impl : Stage {
  using Stage::Stage;
};

DerenderSetup::DerenderSetup(const Session& session, const DerenderOptions& options)
    : impl_(std::make_unique<Impl>(session, options)) {}

DerenderSetup::~DerenderSetup() = default;

size_t DerenderSetup::NumPhotos() const { return impl_->groups.size(); }

void DerenderSetup::ReadPhoto(size_t photo, RadianceWindow* image, double* decode_s) const {
  IBRDF_CHECK(photo < impl_->groups.size()) << "photo " << photo << " of " << impl_->groups.size();
  ReadStagePhoto(*impl_, photo, image, decode_s);
}

void DerenderSetup::DerenderPhoto(size_t photo, const RadianceWindow& image, bool parallel, PhotoSamples* out) const {
  IBRDF_CHECK(photo < impl_->groups.size()) << "photo " << photo << " of " << impl_->groups.size();
  DerenderStagePhoto(*impl_, photo, image, parallel, out);
}

DerenderResult DerenderSetup::DerenderAll() const {
  ColourCorrectionCounts unused;
  return RunStageInMemory(*impl_, {}, &unused);
}

bool DerenderOptions::Check(std::string* why) const {
  // Grazing limits in (0, 90] degrees.
  IBRDF_CHECK_OPTION_GT(max_theta_i_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_i_deg, 90.0);
  IBRDF_CHECK_OPTION_GT(max_theta_e_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_e_deg, 90.0);
  IBRDF_CHECK_OPTION_GE(min_signal, 0.0);
  IBRDF_CHECK_OPTION_GE(pixel_stride, 1);
  IBRDF_CHECK_OPTION_GT(mixed_pixel_depth_factor, 0.0);
  IBRDF_CHECK_OPTION_GE(max_normal_fit_rms_m, 0.0);
  IBRDF_CHECK_OPTION_GE(min_fit_neighbours, 0);
  IBRDF_CHECK_OPTION_GE(shadow_ray_offset_fit_rms, 0.0);
  IBRDF_CHECK_OPTION_GE(shadow_edge_deg, 0.0);
  IBRDF_CHECK_OPTION_LT(shadow_edge_deg, 45.0);
  IBRDF_CHECK_OPTION_RANGE(shadow_edge_rays, 0, 64);
  if (!exposure_advice.Check(why)) return false;
  return true;
}

const std::vector<std::pair<std::string, std::string>>& RejectionReasons() {
  static const std::vector<std::pair<std::string, std::string>> kReasons = {
      {"off_sample", "the pixel's ray misses the sample (background, or a cylinder's end cap)"},
      {"masked", "the pixel sees the sample but the photo's mask (or the session's default mask) excludes it"},
      {"mixed_pixel",
       "mesh: the pixel straddles the silhouette (a corner ray misses, or hits at a very different depth)"},
      {"occluded_by_target", "mesh: a reference marker lies between the camera and the sample"},
      {"low_quality_normal", "mesh: no normal, or its local-plane fit is poor (fit RMS or neighbours out of bounds)"},
      {"backfacing", "mesh: the interpolated or the face normal turns away from the camera"},
      {"unlit", "the light is behind the surface at the hit point"},
      {"grazing_exitance", "theta_e above max_theta_e_deg"},
      {"grazing_incidence", "theta_i above max_theta_i_deg"},
      {"shadowed", "mesh, shadow rays on: the sample itself blocks the light"},
      {"shadow_edge", "mesh, shadow rays on: lit, but within shadow_edge_deg of a shadow edge"},
      {"non_finite", "a pixel value is NaN or infinite"},
      {"saturated", "every channel is unmeasured and one reaches the saturation level"},
      {"below_signal", "every channel's expected linear signal is below min_signal"},
      {"colour_unmeasured",
       "colour chart: the corrected channels all mix an unmeasured one or come out negative (after the pixel tests)"},
  };
  return kReasons;
}

std::string DerenderSummary::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "derender: %llu samples from %llu photos (%llu pixels) in %.2f s; rejected: ",
                static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(photos),
                static_cast<unsigned long long>(pixels_examined), total_s);
  std::string brief = buffer + FormatCounts(rejected);
  const auto triple = [](const std::array<uint64_t, 3>& n) {
    return std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " + std::to_string(n[2]);
  };
  if (channels_not_measured[0] + channels_not_measured[1] + channels_not_measured[2] > 0) {
    brief += "; samples with a channel not measured (R, G, B): " + triple(channels_not_measured);
  }
  if (colour_negative[0] + colour_negative[1] + colour_negative[2] > 0) {
    brief += "; channels negative after the colour correction, so not measured (R, G, B): " + triple(colour_negative);
  }
  return brief;
}

std::vector<Eigen::Vector2f> PixelRays(const Camera& camera) {
  return PixelRaysInBox(camera, PixelBox{0, 0, camera.width, camera.height});
}

std::vector<Eigen::Vector2f> PixelCornerRays(const Camera& camera) {
  return PixelCornerRaysInBox(camera, PixelBox{0, 0, camera.width + 1, camera.height + 1});
}

DerenderResult DerenderAnalytic(const Session& session, const DerenderOptions& options) {
  if (IsMeshSample(session.sample.kind)) {
    ThrowError("sample", "a mesh sample needs the mesh derenderer (Derender); DerenderAnalytic takes a sphere or a "
                         "cylinder");
  }
  return DerenderSetup(session, options).DerenderAll();
}

DerenderResult Derender(const Session& session, const DerenderOptions& options) {
  return DerenderWith(session, options, [](const Stage& stage, const std::vector<Eigen::Matrix3d>& colour,
                                           ColourCorrectionCounts* counts) {
    return RunStageInMemory(stage, colour, counts);
  });
}

nlohmann::json DerenderSidecar(const Session& session, const DerenderOptions& options, const DerenderSummary& summary) {
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, meaning] : RejectionReasons()) {
    const auto it = summary.rejected.find(reason);
    rejected[reason] = it == summary.rejected.end() ? 0 : it->second;
  }
  nlohmann::json sidecar = {
      {"format", "ibrdf-samples"},
      {"version", 1},
      {"session", std::filesystem::absolute(session.manifest_path).lexically_normal().string()},
      {"session_name", session.name},
      {"sample", SampleKindName(session.sample.kind)},
      {"units",
       {{"brdf", "1/sr"},
        {"angles", "radians"},
        {"directions",
         "unit vectors in the local frame, z = surface normal; wi towards the light, wo towards the camera"}}},
      {"colour_space", ColourSpaceDescription(session)},
      // Relative: the lights' common scale is unknown, so is the BRDF's (every value times one constant).
      {"intensity_scale", session.radiometry.relative_intensities ? "relative" : "absolute"},
      {"uncertainty", session.radiometry.noise ? "sigma: one standard deviation from the session's camera noise model"
                                               : "none: the session has no camera noise model; sigma is 0"},
      {"counts",
       {{"photos", summary.photos},
        {"pixels_examined", summary.pixels_examined},
        {"accepted", summary.accepted},
        {"rejected", rejected},
        {"channels_not_measured", summary.channels_not_measured},
        {"colour_negative", summary.colour_negative}}},
      {"validity",
       "per channel, in the samples' `valid` field: 1 measured, 0 clipped, below the signal floor (tested on the "
       "expected signal, the mean of the ring of 16 neighbours at distance 2) or not finite; a pixel is kept while "
       "any channel is measured; with a colour chart, a corrected channel is measured when every camera channel it "
       "mixes is and its value is not negative (counts.colour_negative: those marked unmeasured for their sign)"},
      {"exposure", ExposureJson(summary.exposure, summary.exposure_warnings)},
      {"options",
       {{"max_theta_i_deg", options.max_theta_i_deg},
        {"max_theta_e_deg", options.max_theta_e_deg},
        {"min_signal", options.min_signal},
        {"pixel_stride", options.pixel_stride},
        {"max_saturated_fraction", options.exposure_advice.max_saturated_fraction},
        {"max_below_signal_fraction", options.exposure_advice.max_below_signal_fraction}}},
      {"timings_s", {{"total", summary.total_s}, {"decode_cpu", summary.decode_s}}},
  };
  if (session.colour_chart) sidecar["colour"] = ColourSidecar(session, summary.colour_matrices);
  if (IsMeshSample(session.sample.kind)) {
    sidecar["timings_s"]["mesh_setup"] = summary.mesh_setup_s;
    sidecar["mesh"] = {
        {"file", session.sample.mesh_file},          {"faces", summary.mesh_faces},
        {"shadow_rays", summary.shadow_rays_on},     {"visibility", summary.visibility_reason},
        {"shadow_rays_traced", summary.shadow_rays}, {"shadow_tests_skipped", summary.shadow_tests_skipped}};
    nlohmann::json& o = sidecar["options"];
    o["mask_mixed_pixels"] = options.mask_mixed_pixels;
    o["mixed_pixel_depth_factor"] = options.mixed_pixel_depth_factor;
    o["max_normal_fit_rms_m"] = options.max_normal_fit_rms_m;
    o["min_fit_neighbours"] = options.min_fit_neighbours;
    o["shadow_ray_offset_fit_rms"] = options.shadow_ray_offset_fit_rms;
    o["shadow_edge_deg"] = options.shadow_edge_deg;
    o["shadow_edge_rays"] = options.shadow_edge_rays;
    o["visibility"] = VisibilityName(options.visibility.value_or(session.sample.visibility));
  }
  return sidecar;
}

DerenderSummary DerenderToFile(const Session& session, const DerenderOptions& options,
                               const std::string& samples_path) {
  Log(1, "session " + session.name + ": " + std::to_string(session.photos.size()) + " photos, " +
             SampleKindName(session.sample.kind) + " sample, response " + session.radiometry.response.Describe() +
             (session.radiometry.relative_intensities
                  ? "; lights' intensities relative (known up to one scale): the BRDF's scale is relative too"
                  : ""));
  // The samples and their sidecar as one unit (core/file_util.h): never a new file beside an old sidecar.
  // Each photo's samples are appended to the file as it is done, so memory does not grow with the photos;
  // the file appears under its name only when the stage is complete.
  AtomicFile samples_file(samples_path), sidecar_file(SidecarPath(samples_path));
  SampleFileWriter writer(samples_file.temporary_path());
  const DerenderSummary summary = DerenderWith(
      session, options,
      [&](const Stage& stage, const std::vector<Eigen::Matrix3d>& colour, ColourCorrectionCounts* counts) {
        return RunStage(stage, colour, counts, [&](const std::vector<std::vector<BrdfSample>>& blocks) {
          for (const std::vector<BrdfSample>& block : blocks) writer.Append(block.data(), block.size());
        });
      });
  if (summary.accepted == 0) {
    ThrowError(session.manifest_path,
               "no BRDF samples: every pixel was rejected (" + summary.BriefReport() + "); nothing written");
  }
  IBRDF_CHECK(writer.rows() == summary.accepted) << writer.rows() << " rows written, " << summary.accepted << " accepted";
  writer.Finish();
  WriteJsonFile(sidecar_file.temporary_path(), DerenderSidecar(session, options, summary));
  CommitWithManifest(&samples_file, &sidecar_file);
  Log(1, summary.BriefReport());
  for (const ExposureWarning& warning : summary.exposure_warnings) Log(0, "warning: " + warning.message);
  return summary;
}

}  // namespace ibrdf
