#include "reconstruct/truth_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "core/rgl_bsdf.h"
#include "core/sample_file.h"
#include "core/statistics.h"
#include "core/truth_file.h"

namespace ibrdf {
namespace {

struct Accumulator {
  std::vector<double> abs_rel[3];
  double sum_rel[3] = {0, 0, 0};

  size_t count = 0;  // samples added (each with at least one valid channel)

  // Adds the channels of a sample that are measurements (valid[c]); the others are left out.
  void Add(const Eigen::Vector3d& rel, const uint8_t valid[3]) {
    ++count;
    for (int c = 0; c < 3; ++c) {
      if (!valid[c]) continue;
      abs_rel[c].push_back(std::abs(rel[c]));
      sum_rel[c] += rel[c];
    }
  }
  ErrorStats Finish() {
    ErrorStats stats;
    stats.count = count;
    if (stats.count == 0) return stats;
    for (int c = 0; c < 3; ++c) {
      std::vector<double>& v = abs_rel[c];
      if (v.empty()) continue;
      stats.median[c] = PercentileInPlace(&v, 0.5);
      stats.p95[c] = PercentileInPlace(&v, 0.95);
      stats.bias[c] = sum_rel[c] / double(v.size());
    }
    return stats;
  }
};

nlohmann::json StatsJson(const ErrorStats& stats) {
  auto rgb = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  return {{"count", stats.count},
          {"median_rel_error", rgb(stats.median)},
          {"p95_rel_error", rgb(stats.p95)},
          {"mean_signed_rel_error", rgb(stats.bias)}};
}

// CompareWithTruth's work on samples that come in runs (a vector, or a file's chunks): the truth's values
// in parallel, a block at a time into a reused buffer; the accumulation stays serial and in sample order,
// so the figures are those of the one-thread loop, bit for bit, however the samples are split.
class TruthComparer {
 public:
  TruthComparer(const BrdfModel& truth, const std::vector<double>& band_edges_deg)
      : truth_(truth), edges_(band_edges_deg), bands_(band_edges_deg.size() - 1) {}

  void Add(const BrdfSample* samples, size_t count) {
    for (size_t begin = 0; begin < count; begin += kBlock) {
      const size_t end = std::min(count, begin + kBlock);
      block_.resize(std::max(block_.size(), end - begin));
      tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 1024), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i < range.end(); ++i) Compare(samples[i], &block_[i - begin]);
      });
      for (size_t i = begin; i < end; ++i) {
        const Compared& c = block_[i - begin];
        if (c.zero_truth) {
          ++comparison_.skipped_zero_truth;
          continue;
        }
        overall_.Add(c.rel, samples[i].valid);
        if (c.band >= 0) bands_[c.band].Add(c.rel, samples[i].valid);
      }
    }
  }

  TruthComparison Finish() {
    // The percentiles of the bands and of the whole set, side by side.
    std::vector<ErrorStats> band_stats(bands_.size());
    tbb::parallel_invoke(
        [&] { comparison_.overall = overall_.Finish(); },
        [&] { tbb::parallel_for(size_t(0), bands_.size(), [&](size_t b) { band_stats[b] = bands_[b].Finish(); }); });
    for (size_t b = 0; b < bands_.size(); ++b) {
      comparison_.bands.push_back({edges_[b], edges_[b + 1], band_stats[b]});
    }
    comparison_.success = true;
    return comparison_;
  }

 private:
  static constexpr size_t kBlock = 1 << 16;
  struct Compared {
    Eigen::Vector3d rel;
    int band = -1;  // -1: in no band
    bool zero_truth = false;
  };

  void Compare(const BrdfSample& s, Compared* out) const {
    const Eigen::Vector3d wi = Eigen::Vector3d(s.wi[0], s.wi[1], s.wi[2]).normalized();
    const Eigen::Vector3d wo = Eigen::Vector3d(s.wo[0], s.wo[1], s.wo[2]).normalized();
    const Eigen::Vector3d f_true = truth_.Eval(wi, wo);
    out->zero_truth = !((f_true.array() > 0.0).all());
    if (out->zero_truth) return;
    const Eigen::Vector3d f(s.brdf[0], s.brdf[1], s.brdf[2]);
    out->rel = (f - f_true).cwiseQuotient(f_true);
    const double theta_deg = std::max(s.theta_i, s.theta_e) * 180.0 / M_PI;
    out->band = -1;
    for (size_t b = 0; b + 1 < edges_.size(); ++b) {
      const bool last = b + 2 == edges_.size();
      if (theta_deg >= edges_[b] && (theta_deg < edges_[b + 1] || (last && theta_deg <= edges_[b + 1]))) {
        out->band = int(b);
        break;
      }
    }
  }

  const BrdfModel& truth_;
  const std::vector<double> edges_;
  TruthComparison comparison_;
  Accumulator overall_;
  std::vector<Accumulator> bands_;
  std::vector<Compared> block_;
};

}  // namespace

TruthComparison CompareWithTruth(const std::vector<BrdfSample>& samples, const BrdfModel& truth,
                                 const std::vector<double>& band_edges_deg) {
  IBRDF_CHECK(band_edges_deg.size() >= 2);
  TruthComparer comparer(truth, band_edges_deg);
  comparer.Add(samples.data(), samples.size());
  return comparer.Finish();
}

TruthComparison CompareSampleFileWithTruth(const std::string& samples_path, const BrdfModel& truth,
                                           const std::vector<double>& band_edges_deg) {
  IBRDF_CHECK(band_edges_deg.size() >= 2);
  TruthComparer comparer(truth, band_edges_deg);
  ForEachSampleChunk(samples_path, size_t(1) << 16,
                     [&](const BrdfSample* rows, size_t count, uint64_t) { comparer.Add(rows, count); });
  return comparer.Finish();
}

std::string TruthComparison::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "compare: %zu samples; median relative error R %.3f %%  G %.3f %%  B %.3f %%; p95 R %.2f %%  "
                "G %.2f %%  B %.2f %%",
                overall.count, 100 * overall.median[0], 100 * overall.median[1], 100 * overall.median[2],
                100 * overall.p95[0], 100 * overall.p95[1], 100 * overall.p95[2]);
  return buffer;
}

nlohmann::json ToJson(const TruthComparison& comparison) {
  nlohmann::json bands = nlohmann::json::array();
  for (const ThetaBand& band : comparison.bands) {
    nlohmann::json b = StatsJson(band.stats);
    b["theta_low_deg"] = band.low_deg;
    b["theta_high_deg"] = band.high_deg;
    bands.push_back(b);
  }
  return {{"format", "ibrdf-truth-comparison"},
          {"version", 1},
          {"relative_error", "(f_measured - f_true) / f_true per channel; bands by max(theta_i, theta_e)"},
          {"overall", StatsJson(comparison.overall)},
          {"skipped_zero_truth", comparison.skipped_zero_truth},
          {"bands", bands}};
}

std::unique_ptr<BrdfModel> LoadTruthMaterial(const std::string& truth_path) {
  constexpr int kTruthVersion = 1;  // the one version synth writes
  const nlohmann::json json = ReadJsonFile(truth_path);
  JsonObject root(json, truth_path);
  if (root.String("format") != "ibrdf-truth") ThrowError(root.Where("format"), "expected \"ibrdf-truth\"");
  const int version = root.Integer("version");
  if (version != kTruthVersion) {
    ThrowError(root.Where("version"), "unknown version " + std::to_string(version) + " (this build reads version " +
                                          std::to_string(kTruthVersion) + ")");
  }
  if (root.Has("material_map")) ThrowError(root.Where("material_map"), kSpatiallyVaryingTruth);
  root.String("material_name", "");
  root.Raw("generator");
  std::unique_ptr<BrdfModel> material = MaterialFromJson(root.Raw("material"), truth_path, "/material");
  root.Finish();
  return material;
}

std::unique_ptr<BrdfModel> LoadTruthFile(const std::string& path) {
  if (IsMerlPath(path) || IsRglBsdfPath(path)) return LoadMaterial(path);
  const nlohmann::json json = ReadJsonFile(path);
  if (json.is_object() && json.contains("format")) return LoadTruthMaterial(path);
  return MaterialFromJson(json, path);
}

std::string TruthPathFromSidecar(const std::string& samples_path) {
  namespace fs = std::filesystem;
  const std::string sidecar = SidecarPath(samples_path);
  if (!fs::exists(sidecar)) ThrowError(samples_path, "has no sidecar " + sidecar + "; pass --truth");
  const nlohmann::json json = ReadJsonFile(sidecar);
  if (!json.is_object() || !json.contains("session")) ThrowError(sidecar + ": /session", "missing; pass --truth");
  if (!json["session"].is_string()) {
    ThrowError(sidecar + ": /session", std::string("expected the session's path (a string), got ") +
                                           json["session"].type_name() + "; pass --truth");
  }
  const std::string truth = (fs::path(json["session"].get<std::string>()).parent_path() / "truth.json").string();
  if (!fs::exists(truth)) {
    ThrowError(truth, "does not exist: the samples' session is not synthetic (pass --truth for a known BRDF)");
  }
  return truth;
}

std::string ComparisonTable(const TruthComparison& comparison) {
  std::string table;
  char line[4096];  // room for six %f of any double
  std::snprintf(line, sizeof(line), "%-12s %9s  %-26s  %-26s\n", "theta band", "samples", "median |rel error| R G B %",
                "p95 |rel error| R G B %");
  table += line;
  const auto row = [&](const std::string& name, const ErrorStats& s) {
    std::snprintf(line, sizeof(line), "%-12s %9zu  %7.3f %7.3f %7.3f    %7.2f %7.2f %7.2f\n", name.c_str(), s.count,
                  100 * s.median[0], 100 * s.median[1], 100 * s.median[2], 100 * s.p95[0], 100 * s.p95[1],
                  100 * s.p95[2]);
    table += line;
  };
  for (const ThetaBand& band : comparison.bands) {
    if (band.stats.count == 0) continue;
    row(std::to_string(int(band.low_deg)) + "-" + std::to_string(int(band.high_deg)) + " deg", band.stats);
  }
  row("all", comparison.overall);
  return table;
}

}  // namespace ibrdf
