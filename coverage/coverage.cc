#include "coverage/coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <variant>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_format.h"
#include "derender/analytic_sample.h"
#include "reconstruct/sample_domain.h"

namespace ibrdf {

bool CoverageOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(samples_per_view, 16, 1000000);
  IBRDF_CHECK_OPTION_GT(max_theta_i_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_i_deg, 90.0);
  IBRDF_CHECK_OPTION_GT(max_theta_e_deg, 0.0);
  IBRDF_CHECK_OPTION_LE(max_theta_e_deg, 90.0);
  IBRDF_CHECK_OPTION_RANGE(band_deg, 1.0, 90.0);
  if (!regression.Check(why)) return false;
  return tabulate.Check(why);
}

std::string CoverageResult::BriefReport() const {
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "%llu views, %llu predicted samples (stride %.1f px): measured %.1f %% (%llu of %llu cells), "
                "interpolated %.1f %%; theta_d %.1f to %.1f deg; %.2f s",
                (unsigned long long)views, (unsigned long long)samples, pixel_stride, 100.0 * MeasuredFraction(),
                (unsigned long long)measured, (unsigned long long)cells,
                cells ? 100.0 * double(interpolated) / double(cells) : 0.0, theta_d_min_deg, theta_d_max_deg, seconds);
  return buffer;
}

nlohmann::json ToJson(const CoverageResult& result) {
  nlohmann::json bands = nlohmann::json::array();
  for (const CoverageBand& b : result.bands) {
    bands.push_back({{"theta_h_low_deg", b.theta_h_low_deg},
                     {"theta_h_high_deg", b.theta_h_high_deg},
                     {"cells", b.cells},
                     {"measured", b.measured},
                     {"interpolated", b.interpolated},
                     {"measured_fraction", b.cells ? double(b.measured) / double(b.cells) : 0.0}});
  }
  return {{"views", result.views},
          {"samples", result.samples},
          {"pixel_stride", result.pixel_stride},
          {"cells", result.cells},
          {"measured", result.measured},
          {"interpolated", result.interpolated},
          {"measured_fraction", result.MeasuredFraction()},
          {"theta_d_min_deg", result.theta_d_min_deg},
          {"theta_d_max_deg", result.theta_d_max_deg},
          {"theta_h_bands", bands},
          {"seconds", result.seconds}};
}

namespace {

// The shape of a session's sample, or an Error naming what capture check cannot predict.
AnalyticShape ShapeOf(const SampleSpec& sample) {
  if (IsMeshSample(sample.kind)) {
    ThrowError("coverage", "a mesh sample's coverage is not predicted (only a sphere or cylinder): its normals "
                           "need the scanned mesh and, where it is not convex, its shadows");
  }
  return MakeAnalyticShape(sample);
}

// The pixel rectangle [x0, x1) x [y0, y1) that can see the sample: its bounding sphere's projection,
// widened by 30 % for the lens distortion, clipped to the image. False when the sample is
// behind the camera or off the image.
bool SampleWindow(const Camera& camera, const SampleSpec& sample, const Rigid3d& camera_from_world, double* x0,
                  double* y0, double* x1, double* y1) {
  const double radius = sample.kind == SampleSpec::Kind::kCylinder
                            ? std::hypot(sample.radius, 0.5 * sample.length)
                            : sample.radius;
  const Eigen::Vector3d c = camera_from_world * sample.center;
  if (!(c.z() > radius)) return false;
  const Eigen::Vector2d centre = camera.ImageFromCamera(c);
  const double r_px = 1.3 * std::max(camera.FocalX(), camera.FocalY()) * radius / std::sqrt(c.squaredNorm() - radius * radius);
  *x0 = std::max(0.0, centre.x() - r_px);
  *y0 = std::max(0.0, centre.y() - r_px);
  *x1 = std::min(double(camera.width), centre.x() + r_px);
  *y1 = std::min(double(camera.height), centre.y() + r_px);
  return *x1 > *x0 && *y1 > *y0;
}

}  // namespace

struct ViewTracer::Impl {
  static constexpr int kStep = 4;  // lattice spacing, pixels
  Camera camera;
  SampleSpec sample;
  AnalyticShape shape;
  CoverageOptions options;
  int columns = 0, rows = 0;
  std::vector<Eigen::Vector2d> plane;  // undistorted image-plane points at pixel positions (kStep c, kStep r)

  Impl(const Camera& c, const SampleSpec& s, const CoverageOptions& o) : camera(c), sample(s), shape(ShapeOf(s)), options(o) {
    columns = camera.width / kStep + 2;
    rows = camera.height / kStep + 2;
    plane.resize(size_t(columns) * rows);
    for (int r = 0; r < rows; ++r) {
      for (int col = 0; col < columns; ++col) {
        plane[size_t(r) * columns + col] = camera.CamPlaneFromImage(Eigen::Vector2d(kStep * col, kStep * r));
      }
    }
  }

  Eigen::Vector2d Plane(double x, double y) const {
    const double u = x / kStep, v = y / kStep;
    const int c0 = std::clamp(int(u), 0, columns - 2), r0 = std::clamp(int(v), 0, rows - 2);
    const double fu = u - c0, fv = v - r0;
    const Eigen::Vector2d* p = &plane[size_t(r0) * columns + c0];
    return (1.0 - fv) * ((1.0 - fu) * p[0] + fu * p[1]) + fv * ((1.0 - fu) * p[columns] + fu * p[columns + 1]);
  }

  // Calls `accept(sample)` for each pixel of the grid of stride `stride` over the sample's window whose
  // ray hits the shape lit and within the grazing limits.
  template <typename Accept>
  void Trace(const CoverageView& view, double stride, uint32_t image, Accept&& accept) const {
    double x0, y0, x1, y1;
    if (!SampleWindow(camera, sample, view.camera_from_world, &x0, &y0, &x1, &y1)) return;
    const Rigid3d world_from_camera = view.camera_from_world.Inverse();
    const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
    const Eigen::Vector3d origin = world_from_camera.translation;
    const double cos_max_i = std::cos(options.max_theta_i_deg * kDegree);
    const double cos_max_e = std::cos(options.max_theta_e_deg * kDegree);
    // Grid positions at pixel centres (x + 0.5) of every stride-th pixel, from the window's first pixel.
    const double first_x = std::floor(x0) + 0.5, first_y = std::floor(y0) + 0.5;
    for (double y = first_y; y < y1; y += stride) {
      for (double x = first_x; x < x1; x += stride) {
        const Eigen::Vector2d p = Plane(x, y);
        const Eigen::Vector3d direction = (rotation * Eigen::Vector3d(p.x(), p.y(), 1.0)).normalized();
        SurfaceHit hit;
        const bool hits = std::visit([&](const auto& s) { return s.Intersect(origin, direction, &hit); }, shape);
        if (!hits) continue;
        const Eigen::Vector3d wo_world = -direction;
        const double cos_e = wo_world.dot(hit.normal);
        if (!(cos_e >= cos_max_e)) continue;
        const Incidence incidence = IncidenceAt(view.light, hit.point, hit.normal);
        if (!incidence.lit || !(incidence.cos_theta >= cos_max_i)) continue;
        const LocalFrame frame = LocalFrame::FromNormal(hit.normal);
        const Eigen::Vector3d wi = frame.ToLocal(incidence.wi);
        const Eigen::Vector3d wo = frame.ToLocal(wo_world);
        BrdfSample s;
        for (int c = 0; c < 3; ++c) {
          s.wi[c] = static_cast<float>(wi[c]);
          s.wo[c] = static_cast<float>(wo[c]);
          s.brdf[c] = 1.0f;
          s.sigma[c] = 0.0f;
        }
        // The isotropic angles are left for the regression (it works from wi and wo).
        s.theta_i = static_cast<float>(std::acos(std::clamp(wi.z(), -1.0, 1.0)));
        s.theta_e = static_cast<float>(std::acos(std::clamp(wo.z(), -1.0, 1.0)));
        s.delta_phi = 0.0f;
        s.image = image;
        s.pixel[0] = static_cast<uint32_t>(x);
        s.pixel[1] = static_cast<uint32_t>(y);
        accept(s);
      }
    }
  }
};

ViewTracer::ViewTracer(const Camera& camera, const SampleSpec& sample, const CoverageOptions& options)
    : impl_(std::make_unique<Impl>(camera, sample, options)) {}
ViewTracer::~ViewTracer() = default;

std::vector<BrdfSample> ViewTracer::Samples(const CoverageView& view, double stride, uint32_t image) const {
  if (!(stride >= 1.0)) ThrowError("coverage", "pixel stride " + std::to_string(stride) + " is below 1");
  std::vector<BrdfSample> samples;
  impl_->Trace(view, stride, image, [&](const BrdfSample& s) { samples.push_back(s); });
  return samples;
}

double ViewTracer::Stride(const CoverageView& view, int samples) const {
  double x0, y0, x1, y1;
  if (!SampleWindow(impl_->camera, impl_->sample, view.camera_from_world, &x0, &y0, &x1, &y1)) return 1.0;
  // A coarse grid of about 48 x 48 over the window; the count kept scales with 1 / stride^2.
  const double coarse = std::max(1.0, std::max(x1 - x0, y1 - y0) / 48.0);
  uint64_t kept = 0;
  impl_->Trace(view, coarse, 0, [&](const BrdfSample&) { ++kept; });
  if (kept == 0) return coarse;
  return std::max(1.0, coarse * std::sqrt(double(kept) / double(std::max(1, samples))));
}

std::vector<BrdfSample> PredictSamples(const Camera& camera, const SampleSpec& sample,
                                       const std::vector<CoverageView>& views, const CoverageOptions& options,
                                       double* stride) {
  const ViewTracer tracer(camera, sample, options);
  std::vector<std::vector<BrdfSample>> per_view(views.size());
  std::vector<double> strides(views.size(), 1.0);
  tbb::parallel_for(size_t(0), views.size(), [&](size_t v) {
    strides[v] = tracer.Stride(views[v], options.samples_per_view);
    per_view[v] = tracer.Samples(views[v], strides[v], uint32_t(v));
  });
  std::vector<BrdfSample> samples;
  double largest = 1.0;
  for (size_t v = 0; v < views.size(); ++v) {
    largest = std::max(largest, strides[v]);
    samples.insert(samples.end(), per_view[v].begin(), per_view[v].end());
  }
  if (stride) *stride = largest;
  return samples;
}

std::vector<uint8_t> CellsWithinLimit(double max_theta_deg) {
  const double cos_limit = std::cos(max_theta_deg * kDegree);
  double cos_phi[kMerlPhiD];
  for (int k = 0; k < kMerlPhiD; ++k) cos_phi[k] = std::cos(MerlCellCentre(0, 0, k).phi_d);
  std::vector<uint8_t> inside(kMerlCells, 0);
  for (int i = 0; i < kMerlThetaH; ++i) {
    const double theta_h = MerlCellCentre(i, 0, 0).theta_h;
    for (int j = 0; j < kMerlThetaD; ++j) {
      const double theta_d = MerlCellCentre(0, j, 0).theta_d;
      const double a = std::cos(theta_h) * std::cos(theta_d), b = std::sin(theta_h) * std::sin(theta_d);
      for (int k = 0; k < kMerlPhiD; ++k) {
        const double z1 = a - b * cos_phi[k], z2 = a + b * cos_phi[k];
        inside[MerlFlatIndex(i, j, k)] = z1 > cos_limit && z2 > cos_limit && z1 > 0.0 && z2 > 0.0;
      }
    }
  }
  return inside;
}

CoverageResult SummarizeDomain(const std::vector<uint8_t>& domain, const CoverageOptions& options) {
  if (domain.size() != kMerlCells) {
    ThrowError("coverage", "a domain array of " + std::to_string(domain.size()) + " cells, expected " +
                               std::to_string(kMerlCells) + " (90 x 90 x 180)");
  }
  CoverageResult result;
  const int band_count = int(std::ceil(90.0 / options.band_deg - 1e-9));
  for (int b = 0; b < band_count; ++b) {
    CoverageBand band;
    band.theta_h_low_deg = b * options.band_deg;
    band.theta_h_high_deg = std::min(90.0, (b + 1) * options.band_deg);
    result.bands.push_back(band);
  }
  const std::vector<uint8_t> inside = CellsWithinLimit(options.tabulate.max_theta_deg);
  for (int i = 0; i < kMerlThetaH; ++i) {
    const double theta_h = MerlCellCentre(i, 0, 0).theta_h;
    const int b = std::min(band_count - 1, int(theta_h / kDegree / options.band_deg));
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        if (!inside[MerlFlatIndex(i, j, k)]) continue;
        const uint8_t c = domain[MerlFlatIndex(i, j, k)];
        CoverageBand& band = result.bands[b];
        ++band.cells;
        ++result.cells;
        if (c == uint8_t(DomainClass::kMeasured)) {
          ++band.measured;
          ++result.measured;
        } else if (c == uint8_t(DomainClass::kInterpolated)) {
          ++band.interpolated;
          ++result.interpolated;
        }
      }
    }
  }
  result.success = true;
  return result;
}

CoverageResult ClassifyCoverage(const std::vector<BrdfSample>& samples, double stride, uint64_t views,
                                const CoverageOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("coverage options", why);
  if (samples.empty()) ThrowError("coverage", "no view sees the sample lit within the grazing limits");
  Timer timer;
  LocalRegressionOptions regression = options.regression;
  // A predicted sample stands for stride^2 pixels: the kernel's count of samples is judged at full density.
  regression.min_neighbors = std::max(1, int(std::ceil(double(regression.min_neighbors) / (stride * stride))));
  // The class depends on the support's counts and positions only (local_regression.cc: the growth loop,
  // the centroid and the nearest point), never on the degree: the cheapest fit serves.
  regression.degree = 0;
  const LocalRegression fit(samples, regression);
  TabulateSummary summary;
  std::vector<uint8_t> domain;
  TabulateMerl(fit, options.tabulate, &summary, nullptr, &domain);
  CoverageResult result = SummarizeDomain(domain, options);
  result.domain = std::move(domain);
  result.views = views;
  result.samples = samples.size();
  result.pixel_stride = stride;
  result.theta_d_min_deg = fit.theta_d_min() / kDegree;
  result.theta_d_max_deg = fit.theta_d_max() / kDegree;
  result.seconds = timer.ElapsedSeconds();
  return result;
}

CoverageResult PredictCoverage(const Camera& camera, const SampleSpec& sample, const std::vector<CoverageView>& views,
                               const CoverageOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("coverage options", why);
  if (views.empty()) ThrowError("coverage", "no posed view to predict from");
  Timer timer;
  double stride = 1.0;
  const std::vector<BrdfSample> samples = PredictSamples(camera, sample, views, options, &stride);
  CoverageResult result = ClassifyCoverage(samples, stride, views.size(), options);
  result.seconds = timer.ElapsedSeconds();
  return result;
}

std::vector<CoverageView> SessionViews(const Session& session, std::vector<std::string>* missing) {
  std::vector<CoverageView> views;
  // One view per distinct (pose, light): a bracket's exposures see the same samples.
  std::map<std::pair<std::vector<double>, size_t>, bool> seen;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    if (photo.role != PhotoRole::kMeasurement) continue;
    const Light& light = session.PhotoLight(i);
    if (!photo.camera_from_world) {
      if (missing) missing->push_back("photo " + photo.file + ": no camera_from_world");
      continue;
    }
    if (!light.placement_known) {
      if (missing) missing->push_back("photo " + photo.file + ": " + LightLabel(light) + " placement unknown");
      continue;
    }
    const Rigid3d& pose = *photo.camera_from_world;
    const std::vector<double> key = {pose.rotation.w(), pose.rotation.x(), pose.rotation.y(), pose.rotation.z(),
                                     pose.translation.x(), pose.translation.y(), pose.translation.z()};
    if (seen.count({key, photo.light})) continue;
    seen[{key, photo.light}] = true;
    views.push_back({pose, light});
  }
  return views;
}

}  // namespace ibrdf
