#include "derender/derenderer.h"

#include <array>
#include <atomic>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>

#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/light.h"
#include "derender/analytic_sample.h"
#include "derender/radiance_image.h"

namespace ibrdf {
namespace {

constexpr double kDegree = M_PI / 180.0;

// The pixel box [x0, x1) x [y0, y1) that holds the projection of the sample's bounding sphere in one
// photo, with a 2-pixel margin; the whole image where the cone around the sphere is too wide to
// project (or holds the camera). Pixels outside it cannot see the sample.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

PixelBox SampleBox(const Camera& camera, const Rigid3d& camera_from_world, const AnalyticSample& sample) {
  const PixelBox whole{0, 0, camera.width, camera.height};
  const Eigen::Vector3d c = camera_from_world * sample.BoundingCenter();
  const double distance = c.norm();
  const double radius = sample.BoundingRadius();
  if (!(distance > 1.5 * radius)) return whole;
  const Eigen::Vector3d axis = c / distance;
  const double sin_alpha = radius / distance, cos_alpha = std::sqrt(1.0 - sin_alpha * sin_alpha);
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

}  // namespace

bool DerenderOptions::Check(std::string* why) const {
  if (!(max_theta_i_deg > 0.0 && max_theta_i_deg <= 90.0) || !(max_theta_e_deg > 0.0 && max_theta_e_deg <= 90.0)) {
    *why = "grazing limits must be in (0, 90] degrees";
    return false;
  }
  if (!(min_signal >= 0.0)) {
    *why = "min_signal must not be negative";
    return false;
  }
  if (pixel_stride < 1) {
    *why = "pixel_stride must be at least 1";
    return false;
  }
  return true;
}

const std::vector<std::pair<std::string, std::string>>& RejectionReasons() {
  static const std::vector<std::pair<std::string, std::string>> kReasons = {
      {"off_sample", "the pixel's ray misses the sample (background, or a cylinder's end cap)"},
      {"unlit", "the light is behind the surface at the hit point"},
      {"grazing_exitance", "theta_e above max_theta_e_deg"},
      {"grazing_incidence", "theta_i above max_theta_i_deg"},
      {"non_finite", "a pixel value is NaN or infinite"},
      {"saturated", "a channel reaches the saturation level"},
      {"below_signal", "the darkest channel's linear signal is below min_signal"},
  };
  return kReasons;
}

std::string DerenderSummary::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "derender: %llu samples from %llu photos (%llu pixels) in %.2f s; rejected: ",
                static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(photos),
                static_cast<unsigned long long>(pixels_examined), total_s);
  return buffer + FormatCounts(rejected);
}

std::vector<Eigen::Vector2f> PixelRays(const Camera& camera) {
  std::vector<Eigen::Vector2f> rays(size_t(camera.width) * camera.height);
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < camera.width; ++x) {
        rays[size_t(y) * camera.width + x] =
            camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5)).cast<float>();
      }
    }
  });
  return rays;
}

void DerenderPhoto(const Session& session, size_t photo_index, const RadianceImage& image,
                   const std::vector<Eigen::Vector2f>& rays, const AnalyticSample& sample,
                   const DerenderOptions& options, std::vector<BrdfSample>* samples,
                   RejectionCounts* rejected) {
  const PhotoSpec& photo = session.photos[photo_index];
  const Rigid3d world_from_camera = photo.camera_from_world->Inverse();
  const Eigen::Matrix3d world_from_camera_rotation = world_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d camera_center = world_from_camera.translation;
  const double cos_max_i = std::cos(options.max_theta_i_deg * kDegree);
  const double cos_max_e = std::cos(options.max_theta_e_deg * kDegree);
  const int stride = options.pixel_stride;

  // Counters per reason, in RejectionReasons() order.
  enum { kOff, kUnlit, kGrazingE, kGrazingI, kNonFinite, kSaturated, kBelow, kNumReasons };
  std::array<uint64_t, kNumReasons> counts{};

  // Only the pixels that can see the sample are traced; the others are off the sample by construction.
  const PixelBox box = SampleBox(session.camera, *photo.camera_from_world, sample);
  const int x_start = (box.x0 + stride - 1) / stride * stride, y_start = (box.y0 + stride - 1) / stride * stride;
  uint64_t traced = 0;
  for (int y = y_start; y < box.y1; y += stride) {
    for (int x = x_start; x < box.x1; x += stride) {
      ++traced;
      const Eigen::Vector2f& xy = rays[size_t(y) * image.width + x];
      const Eigen::Vector3d direction =
          (world_from_camera_rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
      SurfaceHit hit;
      if (!sample.Intersect(camera_center, direction, &hit)) {
        ++counts[kOff];
        continue;
      }
      const Incidence incidence = IncidenceAt(session.light, hit.point, hit.normal);
      if (!incidence.lit) {
        ++counts[kUnlit];
        continue;
      }
      const Eigen::Vector3d wo_world = -direction;
      const double cos_e = wo_world.dot(hit.normal);
      if (!(cos_e >= cos_max_e)) {
        ++counts[kGrazingE];
        continue;
      }
      if (!(incidence.cos_theta >= cos_max_i)) {
        ++counts[kGrazingI];
        continue;
      }
      // Pixel values: the radiometric flags in RejectionReasons() order.
      const size_t p = image.Index(x, y);
      const uint8_t flags = image.flags[p];
      if (flags & kPixelNonFinite) {
        ++counts[kNonFinite];
        continue;
      }
      if (flags & kPixelSaturated) {
        ++counts[kSaturated];
        continue;
      }
      if (flags & kPixelBelowSignal) {
        ++counts[kBelow];
        continue;
      }
      const LocalFrame frame = LocalFrame::FromNormal(hit.normal);
      const Eigen::Vector3d wi = frame.ToLocal(incidence.wi);
      const Eigen::Vector3d wo = frame.ToLocal(wo_world);
      const IsotropicAngles angles = ToIsotropic(wi, wo);
      BrdfSample s;
      for (int c = 0; c < 3; ++c) {
        s.wi[c] = static_cast<float>(wi[c]);
        s.wo[c] = static_cast<float>(wo[c]);
        const double irradiance = incidence.irradiance[c];
        s.brdf[c] = static_cast<float>(image.radiance[3 * p + c] / irradiance);
        s.sigma[c] = static_cast<float>(image.sigma[3 * p + c] / irradiance);
      }
      s.theta_i = static_cast<float>(angles.theta_i);
      s.theta_e = static_cast<float>(angles.theta_e);
      s.delta_phi = static_cast<float>(angles.delta_phi);
      s.image = static_cast<uint32_t>(photo_index);
      s.pixel[0] = static_cast<uint32_t>(x);
      s.pixel[1] = static_cast<uint32_t>(y);
      samples->push_back(s);
    }
  }
  const uint64_t examined = uint64_t((image.width + stride - 1) / stride) * uint64_t((image.height + stride - 1) / stride);
  counts[kOff] += examined - traced;
  const auto& reasons = RejectionReasons();
  for (int r = 0; r < kNumReasons; ++r) (*rejected)[reasons[r].first] += counts[r];
}

DerenderResult DerenderAnalytic(const Session& session, const DerenderOptions& options) {
  Timer timer;
  DerenderResult result;
  std::string why;
  if (!options.Check(&why)) ThrowError("derender options", why);
  const std::unique_ptr<AnalyticSample> sample = AnalyticSample::Create(session.sample);
  // Everything that can be checked before decoding is checked first, so a bad session fails at once.
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    const std::string where = session.manifest_path + ": /photos/" + std::to_string(i);
    if (!photo.camera_from_world) {
      ThrowError(where, "photo " + photo.file + " has no camera_from_world pose (run `ibrdf align` first)");
    }
    if (sample->Contains(photo.camera_from_world->Inverse().translation)) {
      ThrowError(where, "the camera centre is inside the sample");
    }
  }
  session.CheckPhotos();

  const std::vector<Eigen::Vector2f> rays = PixelRays(session.camera);
  const std::vector<std::vector<size_t>> groups = ExposureGroups(session);
  std::vector<std::vector<BrdfSample>> per_group(groups.size());
  std::vector<RejectionCounts> per_group_rejected(groups.size());
  std::vector<double> decode_s(groups.size(), 0.0);
  ProgressBar progress("photos", groups.size());
  tbb::parallel_for(size_t(0), groups.size(), [&](size_t g) {
    const RadianceImage image = ReadRadianceImage(session, groups[g], options.min_signal, &decode_s[g]);
    // Room for every examined pixel: only the pages written are touched, and the vector never regrows
    // (regrowth copies and page faults cost more than the per-pixel geometry).
    per_group[g].reserve(size_t((image.width + options.pixel_stride - 1) / options.pixel_stride) *
                         size_t((image.height + options.pixel_stride - 1) / options.pixel_stride));
    DerenderPhoto(session, groups[g].front(), image, rays, *sample, options, &per_group[g], &per_group_rejected[g]);
    progress.Add(1);
  });
  progress.Finish();

  size_t total = 0;
  for (const auto& samples : per_group) total += samples.size();
  result.samples.reserve(total);
  for (size_t g = 0; g < per_group.size(); ++g) {
    result.samples.insert(result.samples.end(), per_group[g].begin(), per_group[g].end());
    for (const auto& [reason, count] : per_group_rejected[g]) result.summary.rejected[reason] += count;
    result.summary.decode_s += decode_s[g];
  }
  const int stride = options.pixel_stride;
  const uint64_t per_image = uint64_t((session.camera.width + stride - 1) / stride) *
                             uint64_t((session.camera.height + stride - 1) / stride);
  const size_t measured = groups.size();
  result.summary.photos = measured;
  result.summary.pixels_examined = per_image * measured;
  result.summary.accepted = result.samples.size();
  result.summary.total_s = timer.ElapsedSeconds();
  result.summary.success = true;
  return result;
}

nlohmann::json DerenderSidecar(const Session& session, const DerenderOptions& options,
                               const DerenderSummary& summary) {
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, meaning] : RejectionReasons()) {
    const auto it = summary.rejected.find(reason);
    rejected[reason] = it == summary.rejected.end() ? 0 : it->second;
  }
  return {
      {"format", "ibrdf-samples"},
      {"version", 1},
      {"session", std::filesystem::absolute(session.manifest_path).lexically_normal().string()},
      {"session_name", session.name},
      {"sample", SampleKindName(session.sample.kind)},
      {"units",
       {{"brdf", "1/sr"},
        {"angles", "radians"},
        {"directions", "unit vectors in the local frame, z = surface normal; wi towards the light, wo towards the camera"}}},
      {"colour_space", "camera RGB, linear (the session's response inverted, black level subtracted)"},
      {"uncertainty", session.radiometry.noise ? "sigma: one standard deviation from the session's camera noise model"
                                               : "none: the session has no camera noise model; sigma is 0"},
      {"counts",
       {{"photos", summary.photos},
        {"pixels_examined", summary.pixels_examined},
        {"accepted", summary.accepted},
        {"rejected", rejected}}},
      {"options",
       {{"max_theta_i_deg", options.max_theta_i_deg},
        {"max_theta_e_deg", options.max_theta_e_deg},
        {"min_signal", options.min_signal},
        {"pixel_stride", options.pixel_stride}}},
      {"timings_s", {{"total", summary.total_s}, {"decode_cpu", summary.decode_s}}},
  };
}

}  // namespace ibrdf
