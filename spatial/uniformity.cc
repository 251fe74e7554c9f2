#include "spatial/uniformity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <unordered_map>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/file_util.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/statistics.h"
#include "spatial/surface_points.h"

namespace ibrdf {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The key of the cell `2^shift` times larger that holds the cell `key` (the same grid origin).
uint64_t CoarserKey(uint64_t key, int shift) {
  uint64_t coarse = 0;
  for (int a = 2; a >= 0; --a) coarse = (coarse << 21) | (((key >> (21 * a)) & ((1u << 21) - 1)) >> shift);
  return coarse;
}

// The finest of the cells 1, 2 and 4 times `fine` at which half the usable samples lie in cells with
// enough of them to be scored: a small capture is judged on coarser cells instead of not at all.
// `usable_in_cell` and `keys` are per fine cell.
int CoarseningShift(const std::vector<uint32_t>& usable_in_cell, const std::vector<uint64_t>& keys,
                    int min_cell_samples, int max_shift) {
  uint64_t total = 0;
  for (uint32_t n : usable_in_cell) total += n;
  for (int shift = 0; shift < max_shift; ++shift) {
    std::unordered_map<uint64_t, uint64_t> count;
    for (size_t c = 0; c < keys.size(); ++c) count[CoarserKey(keys[c], shift)] += usable_in_cell[c];
    uint64_t in_scored = 0;
    for (const auto& [key, n] : count) {
      if (n >= uint64_t(min_cell_samples)) in_scored += n;
    }
    if (2 * in_scored >= total) return shift;
  }
  return max_shift;
}

// What one sample gives the check: its cell and, per channel, sample / reference (NaN where either is
// not usable: a channel not measured, or the reference without data or zero there).
struct Row {
  SurfaceLocator::Outcome outcome = SurfaceLocator::Outcome::kMissed;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  float ratio[3] = {kNaN, kNaN, kNaN};
  float value[3] = {kNaN, kNaN, kNaN};  // the sample's own BRDF value where measured
  float cos_h = 1.0f;                   // of the half vector's angle to the normal
  bool usable = false;
};

Row Examine(const SurfaceLocator& locator, const BrdfModel& reference, const BrdfSample& s) {
  Row row;
  row.outcome = locator.Locate(s, &row.point);
  if (row.outcome != SurfaceLocator::Outcome::kFound) return row;
  const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
  const Eigen::Vector3d f = reference.Eval(wi, wo);
  row.cos_h = float((wi + wo).normalized().z());
  for (int c = 0; c < 3; ++c) {
    if (!s.Valid(c) || !(f[c] > 0.0) || !std::isfinite(f[c])) continue;
    row.ratio[c] = float(s.brdf[c] / f[c]);
    row.value[c] = s.brdf[c];
    row.usable = true;
  }
  return row;
}

// Runs `visit(row, sample)` for every sample of the file, in file order, examining chunks in parallel.
template <class Visit>
uint64_t ForEachRow(const std::string& samples_path, const SurfaceLocator& locator, const BrdfModel& reference,
                    size_t chunk_rows, Visit visit) {
  std::vector<Row> rows;
  return ForEachSampleChunk(samples_path, chunk_rows, [&](const BrdfSample* samples, size_t count, uint64_t) {
    rows.resize(count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i < range.end(); ++i) rows[i] = Examine(locator, reference, samples[i]);
    });
    for (size_t i = 0; i < count; ++i) visit(rows[i], samples[i]);
  });
}

nlohmann::json Vector(const Eigen::Vector3d& v) {
  nlohmann::json a = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) {
    if (std::isfinite(v[c])) {
      a.push_back(v[c]);
    } else {
      a.push_back(nullptr);
    }
  }
  return a;
}

}  // namespace

uint64_t UniformityCellKey(const Eigen::Vector3d& point, const Eigen::Vector3d& origin, double cell_m) {
  uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const int64_t i = std::clamp<int64_t>(int64_t(std::floor((point[a] - origin[a]) / cell_m)), 0, (1 << 21) - 1);
    key = (key << 21) | uint64_t(i);
  }
  return key;
}

void MedianAndStandardError(std::vector<float>* values, double* median, double* standard_error) {
  *median = PercentileInPlace(values, 0.5);
  std::vector<float> deviations(values->size());
  for (size_t i = 0; i < values->size(); ++i) deviations[i] = float(std::abs((*values)[i] - *median));
  *standard_error = 1.4826 * PercentileInPlace(&deviations, 0.5) * 1.2533 / std::sqrt(double(values->size()));
}

bool RatioDeviates(double ratio, double reference, double noise, double deviation, double noise_sigmas) {
  const double relative = ratio / reference;
  const bool off = !(std::abs(std::log(std::max(relative, 1e-12))) <= std::log1p(deviation));
  return off && std::abs(ratio - reference) > noise_sigmas * noise;
}

bool CheckDeviationBound(double deviation, double noise_sigmas, double warn_fraction, double fail_fraction,
                         std::string* why) {
  if (!(deviation > 0.0) || !(noise_sigmas >= 0.0)) {
    *why = "the deviation must be positive and the noise sigmas at least 0";
    return false;
  }
  if (!(warn_fraction > 0.0 && warn_fraction <= fail_fraction && fail_fraction <= 1.0)) {
    *why = "need 0 < warn fraction <= fail fraction <= 1";
    return false;
  }
  return true;
}

bool UniformityOptions::Check(std::string* why) const {
  if (!clusters.Check(why)) return false;
  if (!(cell_m >= 0.0)) {
    *why = "the cell size must be at least 0 (0: automatic)";
    return false;
  }
  if (min_cell_samples < 3) {
    *why = "a cell needs at least 3 samples to be scored";
    return false;
  }
  if (!CheckDeviationBound(deviation, noise_sigmas, warn_fraction, fail_fraction, why)) return false;
  if (chunk_rows == 0) {
    *why = "chunk rows must be positive";
    return false;
  }
  if (!(cluster_min_theta_h_deg >= 0.0 && cluster_min_theta_h_deg < 80.0)) {
    *why = "the clustering's theta_h limit must be in [0, 80) degrees";
    return false;
  }
  return true;
}

UniformityResult MeasureUniformity(const Session& session, const std::string& samples_path, const BrdfModel& reference,
                                   const UniformityOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("uniformity options", why);
  const auto start = std::chrono::steady_clock::now();
  const SurfaceLocator locator(session);
  UniformityResult result;
  result.cell_m = options.cell_m > 0.0 ? options.cell_m : locator.BoundingRadius() / 16.0;  // until coarsened
  result.grid_origin =
      locator.BoundingCenter() - Eigen::Vector3d::Constant(1.5 * locator.BoundingRadius() + result.cell_m);
  const Eigen::Vector3d& origin = result.grid_origin;

  // Per usable sample: its cell and ratios. Per cell: the sum of its points and its count.
  struct Entry {
    uint32_t cell;
    float ratio[3];
    float value[3];
    float cos_h;
  };
  std::vector<Entry> entries;
  std::unordered_map<uint64_t, uint32_t> cell_of_key;
  std::vector<Eigen::Vector3d> point_sums;
  std::vector<uint32_t> located_in_cell;
  std::vector<uint64_t> keys;
  std::vector<uint64_t> usable_per_photo(std::max<size_t>(session.photos.size(), 1), 0);  // picks the map's photo
  result.samples = ForEachRow(samples_path, locator, reference, options.chunk_rows, [&](const Row& row,
                                                                                       const BrdfSample& sample) {
    switch (row.outcome) {
      case SurfaceLocator::Outcome::kFound:
        break;
      case SurfaceLocator::Outcome::kNoPose:
        ++result.no_pose;
        return;
      case SurfaceLocator::Outcome::kMissed:
        ++result.missed;
        return;
      case SurfaceLocator::Outcome::kMismatch:
        ++result.mismatched;
        return;
    }
    ++result.located;
    const auto [it, inserted] =
        cell_of_key.emplace(UniformityCellKey(row.point, origin, result.cell_m), uint32_t(point_sums.size()));
    if (inserted) {
      point_sums.push_back(Eigen::Vector3d::Zero());
      located_in_cell.push_back(0);
      keys.push_back(it->first);
    }
    point_sums[it->second] += row.point;
    ++located_in_cell[it->second];
    if (!row.usable) {
      ++result.no_reference;
      return;
    }
    entries.push_back(Entry{it->second, {row.ratio[0], row.ratio[1], row.ratio[2]},
                            {row.value[0], row.value[1], row.value[2]}, row.cos_h});
    ++usable_per_photo[sample.image];  // Locate found it: a photo of the session
  });

  // Unless the cell is given, cells too sparse to score are merged into cells 2 or 4 times larger.
  if (options.cell_m <= 0.0) {
    std::vector<uint32_t> usable_in_cell(point_sums.size(), 0);
    for (const Entry& e : entries) ++usable_in_cell[e.cell];
    const int shift = CoarseningShift(usable_in_cell, keys, options.min_cell_samples, /*max_shift=*/2);
    if (shift > 0) {
      std::unordered_map<uint64_t, uint32_t> coarse_of_key;
      std::vector<uint32_t> coarse_of_fine(keys.size());
      std::vector<Eigen::Vector3d> coarse_sums;
      std::vector<uint32_t> coarse_located;
      std::vector<uint64_t> coarse_keys;
      for (size_t c = 0; c < keys.size(); ++c) {
        const auto [it, inserted] = coarse_of_key.emplace(CoarserKey(keys[c], shift), uint32_t(coarse_sums.size()));
        if (inserted) {
          coarse_sums.push_back(Eigen::Vector3d::Zero());
          coarse_located.push_back(0);
          coarse_keys.push_back(it->first);
        }
        coarse_of_fine[c] = it->second;
        coarse_sums[it->second] += point_sums[c];
        coarse_located[it->second] += located_in_cell[c];
      }
      for (Entry& e : entries) e.cell = coarse_of_fine[e.cell];
      point_sums = std::move(coarse_sums);
      located_in_cell = std::move(coarse_located);
      keys = std::move(coarse_keys);
      result.cell_m *= double(1 << shift);
    }
  }

  // The entries grouped by cell (a counting sort), then each cell's median ratio and its noise.
  const size_t n_cells = point_sums.size();
  std::vector<size_t> begin(n_cells + 1, 0);
  for (const Entry& e : entries) ++begin[e.cell + 1];
  for (size_t c = 0; c < n_cells; ++c) begin[c + 1] += begin[c];
  std::vector<float> grouped(entries.size() * 3);
  std::vector<float> off_peak_value(entries.size() * 3, kNaN);  // NaN but at theta_h >= cluster_min_theta_h_deg
  {
    const float max_cos_h = float(std::cos(options.cluster_min_theta_h_deg * kDegree));
    std::vector<size_t> next(begin.begin(), begin.end() - 1);
    for (const Entry& e : entries) {
      const size_t at = next[e.cell]++;
      for (int k = 0; k < 3; ++k) grouped[at * 3 + k] = e.ratio[k];
      if (e.cos_h <= max_cos_h) {
        for (int k = 0; k < 3; ++k) off_peak_value[at * 3 + k] = e.value[k];
      }
    }
  }
  entries = {};
  result.cells.resize(n_cells);
  tbb::parallel_for(size_t(0), n_cells, [&](size_t cell) {
    UniformityCell& out = result.cells[cell];
    out.key = keys[cell];
    out.samples = located_in_cell[cell];
    out.centre = point_sums[cell] / double(located_in_cell[cell]);
    std::vector<float> values;
    for (int k = 0; k < 3; ++k) {
      values.clear();
      for (size_t i = begin[cell]; i < begin[cell + 1]; ++i) {
        if (std::isfinite(grouped[i * 3 + k])) values.push_back(grouped[i * 3 + k]);
      }
      if (values.size() < size_t(options.min_cell_samples)) continue;
      MedianAndStandardError(&values, &out.ratio[k], &out.noise[k]);
      values.clear();
      for (size_t i = begin[cell]; i < begin[cell + 1]; ++i) {
        if (std::isfinite(off_peak_value[i * 3 + k])) values.push_back(off_peak_value[i * 3 + k]);
      }
      if (values.size() >= size_t(options.min_cell_samples)) out.off_peak_brdf[k] = PercentileInPlace(&values, 0.5);
    }
  });

  // The object's ratio per channel, then each cell's deviation from it.
  std::vector<double> per_channel[3];
  for (const UniformityCell& cell : result.cells) {
    for (int k = 0; k < 3; ++k) {
      if (std::isfinite(cell.ratio[k])) per_channel[k].push_back(cell.ratio[k]);
    }
  }
  for (int k = 0; k < 3; ++k) {
    if (!per_channel[k].empty()) result.object_ratio[k] = Median(per_channel[k]);
  }
  std::vector<double> relative[3];
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (UniformityCell& cell : result.cells) {
    bool scored = false;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(cell.ratio[k]) || !(result.object_ratio[k] > 0.0)) continue;
      scored = true;
      const double r = cell.ratio[k] / result.object_ratio[k];
      relative[k].push_back(r);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
      if (RatioDeviates(cell.ratio[k], result.object_ratio[k], cell.noise[k], options.deviation, options.noise_sigmas)) {
        cell.deviates = true;
      }
    }
    if (scored) ++result.cells_scored;
    if (cell.deviates) ++result.cells_deviating;
  }
  for (int k = 0; k < 3; ++k) {
    if (relative[k].size() >= 2) {
      result.spread[k] = Percentile(relative[k], 0.9) / std::max(Percentile(relative[k], 0.1), 1e-12);
    }
  }
  result.min_ratio = result.cells_scored ? lo : 0.0;
  result.max_ratio = hi;
  result.deviating_fraction = result.cells_scored ? double(result.cells_deviating) / double(result.cells_scored) : 0.0;

  {
    // Grouped by their BRDF values away from the peaks, relative to the median cell's: there a
    // material's value hardly changes with the directions each cell saw (its diffuse part), while its
    // ratio to the reconstructed average does (the average is another mix at each direction).
    Eigen::Vector3d object_off_peak = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    for (int k = 0; k < 3; ++k) {
      std::vector<double> values;
      for (const UniformityCell& cell : result.cells) {
        if (std::isfinite(cell.off_peak_brdf[k])) values.push_back(cell.off_peak_brdf[k]);
      }
      if (!values.empty()) object_off_peak[k] = Median(values);
    }
    std::vector<Eigen::Vector3d> relative_ratio;
    for (const UniformityCell& cell : result.cells) {
      relative_ratio.push_back(cell.off_peak_brdf.cwiseQuotient(object_off_peak));
    }
    result.materials = ClusterMaterials(relative_ratio, options.clusters);
    result.cluster_min_theta_h_deg = options.cluster_min_theta_h_deg;
    result.object_off_peak_brdf = object_off_peak;
  }

  result.map_photo = size_t(std::max_element(usable_per_photo.begin(), usable_per_photo.end()) - usable_per_photo.begin());

  const std::string bound = "under " + Fixed(100.0 * options.warn_fraction, 0) + " % of cells (warn), " +
                            Fixed(100.0 * options.fail_fraction, 0) + " % (fail)";
  const std::string remedy =
      "the sample is not one material, and the one BRDF averages its materials, or its geometry is wrong (the "
      "sample's shape or pose, the cameras, the light: see align's verdicts); where: the map, uniformity/map.png; "
      "measure each material (ibrdf run --spatial), one material's region alone (a session mask), or accept the "
      "average";
  if (result.cells_scored < 8) {
    result.verdicts.push_back(MakeVerdict(
        "uniformity.cells", double(result.cells_scored),
        std::to_string(result.cells_scored) + " cells of " + Fixed(result.cell_m * 1e3, 1) +
            " mm with at least " + std::to_string(options.min_cell_samples) + " samples",
        "at least 8 scored cells to judge uniformity", VerdictLevel::kWarn,
        "uniformity not judged: too few samples per cell (a larger --cell-mm, or more photos)"));
  } else {
    result.verdicts.push_back(MakeVerdict(
        "uniformity.cells", result.deviating_fraction,
        std::to_string(result.cells_deviating) + " of " + std::to_string(result.cells_scored) + " cells (" +
            Fixed(100.0 * result.deviating_fraction, 1) + " %) differ from the object's BRDF by over " +
            Fixed(1.0 + options.deviation, 2) + "x and " + Fixed(options.noise_sigmas, 0) +
            " sigma; cell ratios " + Fixed(result.min_ratio, 2) + "x to " + Fixed(result.max_ratio, 2) + "x; " +
            result.materials.BriefReport(),
        bound, VerdictAbove(result.deviating_fraction, options.warn_fraction, options.fail_fraction), remedy));
  }
  const double located_fraction = result.samples ? double(result.located) / double(result.samples) : 0.0;
  result.verdicts.push_back(MakeVerdict(
      "uniformity.located", located_fraction,
      Fixed(100.0 * located_fraction, 2) + " % of " + std::to_string(result.samples) +
          " samples found again on the sample's surface (missed " + std::to_string(result.missed) + ", other angle " +
          std::to_string(result.mismatched) + ", no pose " + std::to_string(result.no_pose) + ")",
      "at least 99 % (warn), 95 % (fail)", VerdictBelow(located_fraction, 0.99, 0.95),
      "the samples were not derendered through this session's geometry: pass the session the samples came from "
      "(--session), or derender again after align"));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::string UniformityResult::BriefReport() const {
  std::string text = "uniformity: " + std::to_string(cells_deviating) + " of " + std::to_string(cells_scored) +
                     " cells of " + Fixed(cell_m * 1e3, 1) + " mm (" + Fixed(100.0 * deviating_fraction, 1) +
                     " %) deviate from the object's BRDF; spread (p90/p10)";
  for (int k = 0; k < 3; ++k) text += " " + (std::isfinite(spread[k]) ? Fixed(spread[k], 2) + "x" : std::string("n/a"));
  text += "; " + materials.BriefReport() + "; " + std::to_string(located) + " of " + std::to_string(samples) +
          " samples located in " + Fixed(seconds, 1) + " s";
  return text;
}

nlohmann::json UniformityResult::ToJson(bool with_cells) const {
  nlohmann::json value = {
      {"format", "ibrdf-uniformity"},
      {"version", 1},
      {"cell_m", cell_m},
      {"grid_origin", Vector(grid_origin)},
      {"samples",
       {{"rows", samples},
        {"located", located},
        {"missed", missed},
        {"other_angle", mismatched},
        {"no_pose", no_pose},
        {"no_reference", no_reference}}},
      {"cells", {{"located", this->cells.size()}, {"scored", cells_scored}, {"deviating", cells_deviating}}},
      {"deviating_fraction", deviating_fraction},
      {"object_ratio", Vector(object_ratio)},
      {"spread_p90_p10", Vector(spread)},
      {"cell_ratio_range", {min_ratio, max_ratio}},
      {"map_photo", map_photo},
      {"materials", materials.ToJson()},
      {"cluster_min_theta_h_deg", cluster_min_theta_h_deg},
      {"object_off_peak_brdf", Vector(object_off_peak_brdf)},
      {"verdicts", VerdictsToJson(verdicts)},
      {"timings_s", {{"total", seconds}}},
  };
  if (with_cells) {
    nlohmann::json list = nlohmann::json::array();
    for (size_t c = 0; c < this->cells.size(); ++c) {
      const UniformityCell& cell = this->cells[c];
      list.push_back({{"key", cell.key},
                      {"centre", Vector(cell.centre)},
                      {"material", c < materials.cell_label.size() ? materials.cell_label[c] : -1},
                      {"samples", cell.samples},
                      {"ratio", Vector(cell.ratio)},
                      {"noise", Vector(cell.noise)},
                      {"off_peak_brdf", Vector(cell.off_peak_brdf)},
                      {"deviates", cell.deviates}});
    }
    value["cell_list"] = list;
  }
  return value;
}

Image UniformityMap(const Session& session, const std::string& samples_path, const UniformityResult& result,
                    const UniformityOptions& options) {
  const SurfaceLocator locator(session);
  const Camera& camera = session.camera;
  Image map(camera.width, camera.height, 3);
  // The photo in grey (the square root of its luminance over its 99th percentile) as the background.
  if (result.map_photo < session.photos.size()) {
    const Image photo = ReadImage(ResolvePath(session.directory, session.photos[result.map_photo].file));
    if (photo.width == camera.width && photo.height == camera.height) {
      std::vector<float> luminance(size_t(photo.width) * photo.height);
      for (size_t i = 0; i < luminance.size(); ++i) {
        const float* p = &photo.pixels[i * photo.channels];
        luminance[i] = photo.channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
      }
      std::vector<float> sorted = luminance;
      const float top = std::max(PercentileInPlace(&sorted, 0.99), 1e-6f);
      for (size_t i = 0; i < luminance.size(); ++i) {
        const float grey = 0.7f * std::sqrt(std::clamp(luminance[i] / top, 0.0f, 1.0f));
        for (int c = 0; c < 3; ++c) map.pixels[i * 3 + c] = grey;
      }
    }
  }
  std::unordered_map<uint64_t, uint32_t> cell_of_key;
  for (size_t i = 0; i < result.cells.size(); ++i) cell_of_key.emplace(result.cells[i].key, uint32_t(i));
  ForEachSampleChunk(samples_path, options.chunk_rows, [&](const BrdfSample* samples, size_t count, uint64_t) {
    for (size_t i = 0; i < count; ++i) {
      const BrdfSample& s = samples[i];
      if (s.image != result.map_photo) continue;
      Eigen::Vector3d point;
      if (locator.Locate(s, &point) != SurfaceLocator::Outcome::kFound) continue;
      const auto it = cell_of_key.find(UniformityCellKey(point, result.grid_origin, result.cell_m));
      if (it == cell_of_key.end()) continue;
      const UniformityCell& cell = result.cells[it->second];
      // The channel furthest from the object's ratio.
      double worst = 0.0;
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(cell.ratio[k]) || !(result.object_ratio[k] > 0.0)) continue;
        const double l = std::log2(std::max(cell.ratio[k] / result.object_ratio[k], 1e-12));
        if (std::abs(l) > std::abs(worst)) worst = l;
      }
      const float t = float(std::clamp(worst, -1.0, 1.0)) * (cell.deviates ? 1.0f : 0.5f);
      const float colour[3] = {t < 0 ? 1.0f + t : 1.0f, 1.0f - std::abs(t), t > 0 ? 1.0f - t : 1.0f};
      if (s.pixel[0] >= uint32_t(camera.width) || s.pixel[1] >= uint32_t(camera.height)) continue;
      const size_t at = (size_t(s.pixel[1]) * camera.width + s.pixel[0]) * 3;
      for (int c = 0; c < 3; ++c) map.pixels[at + c] = colour[c];
    }
  });
  return map;
}

}  // namespace ibrdf
