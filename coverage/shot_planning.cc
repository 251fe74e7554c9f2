#include "coverage/shot_planning.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_format.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/png_writer.h"

namespace ibrdf {

bool ShotPlanOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(suggestions, 0, 1000);
  IBRDF_CHECK_OPTION_GE(distance_m, 0.0);
  IBRDF_CHECK_OPTION_LE(distance_m, 1000.0);
  IBRDF_CHECK_OPTION_GE(min_elevation_deg, -89.0);
  IBRDF_CHECK_OPTION_LE(max_elevation_deg, 89.0);
  IBRDF_CHECK_OPTION_LE(min_elevation_deg, max_elevation_deg);
  IBRDF_CHECK_OPTION_GE(elevation_step_deg, 1.0);
  IBRDF_CHECK_OPTION_GE(min_azimuth_deg, -360.0);
  IBRDF_CHECK_OPTION_LE(max_azimuth_deg, 360.0);
  IBRDF_CHECK_OPTION_LE(min_azimuth_deg, max_azimuth_deg);
  IBRDF_CHECK_OPTION_GE(azimuth_step_deg, 1.0);
  IBRDF_CHECK_OPTION_RANGE(min_light_separation_deg, 0.0, 180.0);
  IBRDF_CHECK_OPTION_RANGE(specular_theta_h_deg, 0.0, 90.0);
  IBRDF_CHECK_OPTION_GT(specular_weight, 0.0);
  IBRDF_CHECK_OPTION_LE(specular_weight, 1e6);
  IBRDF_CHECK_OPTION_RANGE(candidate_samples_per_view, 16, 1000000);
  return coverage.Check(why);
}

std::string ShotPlan::BriefReport() const {
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "%zu photos suggested from %llu candidates at %.3f m: measured %.1f %% -> %.1f %% of %llu cells; %.2f s",
                suggestions.size(), (unsigned long long)candidates, distance_m, 100.0 * before.MeasuredFraction(),
                100.0 * after.MeasuredFraction(), (unsigned long long)after.cells, seconds);
  return buffer;
}

nlohmann::json ToJson(const ShotPlan& plan) {
  nlohmann::json list = nlohmann::json::array();
  for (const ShotSuggestion& s : plan.suggestions) {
    const Eigen::Quaterniond& q = s.camera_from_world.rotation;
    const Eigen::Vector3d& t = s.camera_from_world.translation;
    list.push_back({{"position", {s.position.x(), s.position.y(), s.position.z()}},
                    {"look_at", {s.look_at.x(), s.look_at.y(), s.look_at.z()}},
                    {"azimuth_deg", s.azimuth_deg},
                    {"elevation_deg", s.elevation_deg},
                    {"distance_m", s.distance_m},
                    {"camera_from_world",
                     {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", {t.x(), t.y(), t.z()}}}},
                    {"cells_gained", s.cells_gained},
                    {"weighted_gain", s.weighted_gain}});
  }
  return {{"candidates", plan.candidates},
          {"distance_m", plan.distance_m},
          {"suggestions", list},
          {"coverage_before", ToJson(plan.before)},
          {"coverage_after", ToJson(plan.after)},
          {"seconds", plan.seconds}};
}

namespace {

// The canonical half of the MERL grid under the regression's folds: phi_d cells 0..89 (reciprocity and
// bilateral symmetry map every phi_d into [0, pi/2], reconstruct/local_regression.h); a bitset, one
// row of whole words per theta_d cell, so that a range of theta_d is a range of words.
constexpr int kCanonicalPhi = kMerlPhiD / 2;
constexpr size_t kRowWords = (size_t(kMerlThetaH) * kCanonicalPhi + 63) / 64;
constexpr size_t kWords = kRowWords * kMerlThetaD;
using CellBits = std::vector<uint64_t>;

inline size_t CanonicalIndex(int i, int j, int k) {
  return size_t(j) * kRowWords * 64 + size_t(i) * kCanonicalPhi + k;
}
inline void SetBit(CellBits* bits, size_t index) { (*bits)[index >> 6] |= uint64_t(1) << (index & 63); }

// The theta_d cells whose centres lie within [low, high] (radians): the reconstruction counts no cell
// beyond the samples' theta_d range as measured (reconstruct/sample_domain.cc, ClassifyEstimate).
struct ThetaDRange {
  double low = 1e9, high = -1e9;
  void Add(const ThetaDRange& o) {
    low = std::min(low, o.low);
    high = std::max(high, o.high);
  }
  int FirstCell() const { return std::max(0, int(std::ceil(low / (0.5 * kPi / kMerlThetaD) - 0.5))); }
  int LastCell() const { return std::min(kMerlThetaD - 1, int(std::floor(high / (0.5 * kPi / kMerlThetaD) - 0.5))); }
};

// Marks the canonical cells whose centre lies within the measured distance of a sample: the ellipsoid
// of radii r_h (u, v) and r_d (w), radians, with the folds' mirror images of the sample.
// `range` gets the samples' theta_d range.
void MarkCells(const std::vector<BrdfSample>& samples, double r_h, double r_d, CellBits* bits, ThetaDRange* range) {
  const double d_theta_d = 0.5 * kPi / kMerlThetaD, d_phi = kPi / kMerlPhiD;
  for (const BrdfSample& s : samples) {
    HalfDiffAngles a;
    if (!ToHalfDiff(Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]), Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]), &a)) continue;
    range->low = std::min(range->low, a.theta_d);
    range->high = std::max(range->high, a.theta_d);
    double c = std::fmod(a.phi_d, kPi);
    if (c < 0.0) c += kPi;
    if (c > 0.5 * kPi) c = kPi - c;
    const int j_lo = std::max(0, int(std::floor((a.theta_d - r_d) / d_theta_d - 0.5)));
    const int j_hi = std::min(kMerlThetaD - 1, int(std::ceil((a.theta_d + r_d) / d_theta_d - 0.5)));
    for (int j = j_lo; j <= j_hi; ++j) {
      const double dw = (j + 0.5) * d_theta_d - a.theta_d;
      if (std::abs(dw) > r_d) continue;
      const double r = r_h * std::sqrt(1.0 - (dw / r_d) * (dw / r_d));
      const int i_lo = MerlThetaHalfIndex(std::max(0.0, a.theta_h - r));
      const int i_hi = MerlThetaHalfIndex(a.theta_h + r);
      for (int i = i_lo; i <= i_hi; ++i) {
        const double tc = MerlCellCentre(i, j, 0).theta_h;
        if (std::abs(tc - a.theta_h) > r) continue;
        // |(u, v)_cell - (u, v)_sample| <= r: cos(delta phi) >= (tc^2 + ts^2 - r^2) / (2 tc ts).
        const double product = 2.0 * tc * a.theta_h;
        double half_width;
        if (product < 1e-12) {
          if (tc * tc + a.theta_h * a.theta_h > r * r) continue;
          half_width = kPi;
        } else {
          const double bound = (tc * tc + a.theta_h * a.theta_h - r * r) / product;
          if (bound > 1.0) continue;
          half_width = bound <= -1.0 ? kPi : std::acos(bound);
        }
        // The sample's images in [0, pi/2]'s neighbourhood: c, -c and pi - c.
        for (const double centre : {c, -c, kPi - c}) {
          const double lo = std::max(0.0, centre - half_width), hi = std::min(0.5 * kPi, centre + half_width);
          if (lo > hi) continue;
          const int k_lo = std::max(0, int(std::ceil(lo / d_phi - 0.5)));
          const int k_hi = std::min(kCanonicalPhi - 1, int(std::floor(hi / d_phi - 0.5)));
          for (int k = k_lo; k <= k_hi; ++k) SetBit(bits, CanonicalIndex(i, j, k));
        }
      }
    }
  }
}

struct Candidate {
  double azimuth_deg = 0.0, elevation_deg = 0.0;
  Eigen::Vector3d position;
  CellBits bits;
  ThetaDRange range;
};

// Cells of `bits` (with `more` OR-ed in, when given) that count within `range`: plain and specular.
void CountCells(const CellBits& bits, const CellBits* more, const ThetaDRange& range, const CellBits& valid,
                const CellBits& specular, uint64_t* plain, uint64_t* peak) {
  *plain = *peak = 0;
  const int first = range.FirstCell(), last = range.LastCell();
  if (first > last) return;
  for (size_t w = size_t(first) * kRowWords; w < size_t(last + 1) * kRowWords; ++w) {
    const uint64_t cells = (more ? bits[w] | (*more)[w] : bits[w]) & valid[w];
    *peak += __builtin_popcountll(cells & specular[w]);
    *plain += __builtin_popcountll(cells & ~specular[w]);
  }
}

// The degree range [low, high] in steps (inclusive, the end once; a full turn without its duplicate).
std::vector<double> Steps(double low, double high, double step, bool full_turn) {
  std::vector<double> values;
  const int count = int(std::floor((high - low) / step + 1e-9));
  for (int n = 0; n <= count; ++n) {
    const double v = low + n * step;
    if (full_turn && v >= low + 360.0 - 1e-9) break;
    values.push_back(v);
  }
  return values;
}

}  // namespace

ShotPlan PlanShots(const Camera& camera, const SampleSpec& sample, const std::vector<CoverageView>& views,
                   const ShotPlanOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("shot planning options", why);
  if (views.empty()) ThrowError("shot planning", "no posed view to plan from");
  Timer timer;
  ShotPlan plan;
  const CoverageOptions& coverage = options.coverage;
  const Eigen::Vector3d centre = sample.center;
  double distance = options.distance_m;
  if (distance == 0.0) {
    for (const CoverageView& v : views) distance += (v.camera_from_world.Inverse().translation - centre).norm();
    distance /= double(views.size());
  }
  plan.distance_m = distance;
  const Light& light = views.front().light;

  double stride = 1.0;
  std::vector<BrdfSample> samples = PredictSamples(camera, sample, views, coverage, &stride);
  plan.before = ClassifyCoverage(samples, stride, views.size(), coverage);
  plan.after = plan.before;
  if (options.suggestions == 0) {
    plan.seconds = timer.ElapsedSeconds();
    plan.success = true;
    return plan;
  }

  const double r_h = coverage.regression.radius_h_deg * coverage.tabulate.domain.measured_nearest * kDegree;
  const double r_d = coverage.regression.radius_d_deg * coverage.tabulate.domain.measured_nearest * kDegree;
  // The cells that count: within the theta limit (as TabulateMerl tests it), each with its weight class.
  CellBits valid(kWords, 0), specular(kWords, 0);
  const std::vector<uint8_t> inside = CellsWithinLimit(coverage.tabulate.max_theta_deg);
  for (int i = 0; i < kMerlThetaH; ++i) {
    const bool peak = MerlCellCentre(i, 0, 0).theta_h < options.specular_theta_h_deg * kDegree;
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kCanonicalPhi; ++k) {
        if (!inside[MerlFlatIndex(i, j, k)]) continue;
        SetBit(&valid, CanonicalIndex(i, j, k));
        if (peak) SetBit(&specular, CanonicalIndex(i, j, k));
      }
    }
  }
  CellBits covered(kWords, 0);
  ThetaDRange covered_range;
  MarkCells(samples, r_h, r_d, &covered, &covered_range);

  std::vector<Candidate> candidates;
  const Eigen::Vector3d to_light = DirectionToLight(light, centre);
  const bool full_turn = options.max_azimuth_deg - options.min_azimuth_deg >= 360.0 - 1e-9;
  for (double elevation : Steps(options.min_elevation_deg, options.max_elevation_deg, options.elevation_step_deg, false)) {
    for (double azimuth : Steps(options.min_azimuth_deg, options.max_azimuth_deg, options.azimuth_step_deg, full_turn)) {
      const Eigen::Vector3d direction(std::cos(elevation * kDegree) * std::cos(azimuth * kDegree),
                                      std::cos(elevation * kDegree) * std::sin(azimuth * kDegree),
                                      std::sin(elevation * kDegree));
      if (std::acos(std::clamp(direction.dot(to_light), -1.0, 1.0)) < options.min_light_separation_deg * kDegree) continue;
      Candidate c;
      c.azimuth_deg = azimuth;
      c.elevation_deg = elevation;
      c.position = centre + distance * direction;
      candidates.push_back(std::move(c));
    }
  }
  plan.candidates = candidates.size();
  const ViewTracer tracer(camera, sample, coverage);
  tbb::parallel_for(size_t(0), candidates.size(), [&](size_t n) {
    Candidate& c = candidates[n];
    const CoverageView view{LookAtCameraFromWorld(c.position, centre, Eigen::Vector3d::UnitZ()), light};
    const double candidate_stride = tracer.Stride(view, options.candidate_samples_per_view);
    const std::vector<BrdfSample> candidate_samples = tracer.Samples(view, candidate_stride, 0);
    c.bits.assign(kWords, 0);
    MarkCells(candidate_samples, r_h, r_d, &c.bits, &c.range);
  });

  std::vector<bool> taken(candidates.size(), false);
  for (int step = 0; step < options.suggestions; ++step) {
    double best_gain = 0.0;
    uint64_t best_cells = 0;
    int best = -1;
    uint64_t plain_now = 0, peak_now = 0;
    CountCells(covered, nullptr, covered_range, valid, specular, &plain_now, &peak_now);
    const double score_now = double(plain_now) + options.specular_weight * double(peak_now);
    for (size_t n = 0; n < candidates.size(); ++n) {
      if (taken[n]) continue;
      // The cells it brings within the measured distance, and those its theta_d range opens to them.
      ThetaDRange range = covered_range;
      range.Add(candidates[n].range);
      uint64_t plain = 0, peak = 0;
      CountCells(covered, &candidates[n].bits, range, valid, specular, &plain, &peak);
      const double gain = double(plain) + options.specular_weight * double(peak) - score_now;
      if (gain > best_gain) {
        best_gain = gain;
        best_cells = plain + peak - plain_now - peak_now;
        best = int(n);
      }
    }
    if (best < 0) break;  // no candidate adds a cell
    taken[best] = true;
    const Candidate& c = candidates[best];
    for (size_t w = 0; w < kWords; ++w) covered[w] |= c.bits[w];
    covered_range.Add(c.range);
    ShotSuggestion s;
    s.position = c.position;
    s.look_at = centre;
    s.azimuth_deg = c.azimuth_deg;
    s.elevation_deg = c.elevation_deg;
    s.distance_m = distance;
    s.camera_from_world = LookAtCameraFromWorld(c.position, centre, Eigen::Vector3d::UnitZ());
    s.cells_gained = 2 * best_cells;  // each canonical cell and its bilateral mirror
    s.weighted_gain = best_gain;
    plan.suggestions.push_back(s);
    // The chosen view at the density of the session's views, for the classification after.
    const CoverageView view{s.camera_from_world, light};
    const double view_stride = tracer.Stride(view, coverage.samples_per_view);
    const std::vector<BrdfSample> view_samples =
        tracer.Samples(view, view_stride, uint32_t(views.size() + plan.suggestions.size() - 1));
    samples.insert(samples.end(), view_samples.begin(), view_samples.end());
    stride = std::max(stride, view_stride);
  }
  plan.after = plan.suggestions.empty() ? plan.before
                                        : ClassifyCoverage(samples, stride, views.size() + plan.suggestions.size(), coverage);
  plan.seconds = timer.ElapsedSeconds();
  plan.success = true;
  return plan;
}

void WriteCoveragePicture(const ShotPlan& plan, const std::string& path) {
  constexpr int kScale = 4, kGap = 8;
  const int map = kMerlThetaH * kScale;
  Image image(2 * map + kGap, map, 3);
  // Per (theta_h, theta_d): the fraction of phi_d cells measured, and whether any is within the limit.
  auto fractions = [](const std::vector<uint8_t>& domain, std::vector<double>* measured, std::vector<bool>* any) {
    measured->assign(size_t(kMerlThetaH) * kMerlThetaD, 0.0);
    any->assign(size_t(kMerlThetaH) * kMerlThetaD, false);
    if (domain.size() != kMerlCells) return;
    for (int i = 0; i < kMerlThetaH; ++i) {
      for (int j = 0; j < kMerlThetaD; ++j) {
        int count = 0;
        for (int k = 0; k < kMerlPhiD; ++k) count += domain[MerlFlatIndex(i, j, k)] == 2;
        (*measured)[size_t(i) * kMerlThetaD + j] = double(count) / kMerlPhiD;
      }
    }
  };
  std::vector<double> before, after;
  std::vector<bool> unused;
  fractions(plan.before.domain, &before, &unused);
  fractions(plan.after.domain, &after, &unused);
  for (int y = 0; y < map; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const int panel = x < map ? 0 : (x >= map + kGap ? 1 : -1);
      Eigen::Vector3f rgb(1.0f, 1.0f, 1.0f);
      if (panel >= 0) {
        const int i = y / kScale, j = (x - panel * (map + kGap)) / kScale;
        const double b = before[size_t(i) * kMerlThetaD + j];
        const double a = after[size_t(i) * kMerlThetaD + j];
        const float grey = float(0.15 + 0.85 * (panel == 0 ? b : std::min(a, b)));
        rgb = Eigen::Vector3f(grey, grey, grey);
        if (panel == 1 && a > b) {
          const float t = float(std::min(1.0, (a - b) * 2.0 + 0.3));
          rgb = (1.0f - t) * rgb + t * Eigen::Vector3f(1.0f, 0.55f, 0.0f);
        }
      }
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = rgb[c];
    }
  }
  WritePlainPng(path, image, PixelFormat::kUint8, PngEncoding::kAsOpenImageIo);
}

void WriteCaptureCheck(const Session& session, const ShotPlan& plan, const std::vector<std::string>& missing,
                       const std::string& out_dir, bool overwrite) {
  AtomicDirectory out(out_dir, overwrite);
  nlohmann::json photos = nlohmann::json::array();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    if (photo.role != PhotoRole::kMeasurement) continue;
    const Light& light = session.PhotoLight(i);
    photos.push_back({{"file", photo.file},
                      {"pose", photo.camera_from_world.has_value()},
                      {"light", light.id},
                      {"light_placed", light.placement_known}});
  }
  nlohmann::json report = ToJson(plan);
  report["format"] = "ibrdf-capture-check";
  report["session"] = session.manifest_path;
  report["sample"] = SampleKindName(session.sample.kind);
  report["photos"] = photos;
  report["missing"] = missing;
  report["occlusion"] = "not modelled: a convex sample never shadows itself; other objects are not in the session";
  WriteJsonFile(out.temporary_path() + "/capture-check.json", report);
  WriteCoveragePicture(plan, out.temporary_path() + "/coverage.png");
  out.Commit();
}

}  // namespace ibrdf
