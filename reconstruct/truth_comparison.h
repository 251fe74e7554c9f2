// Measured samples against the true BRDF of a synthetic session: relative error per sample and per
// colour channel, summarized overall and by theta band (bands of max(theta_i, theta_e), since error
// grows towards grazing on either side).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "core/brdf_model.h"
#include "core/sample_file.h"

namespace ibrdf {

struct ErrorStats {
  size_t count = 0;
  Eigen::Vector3d median = Eigen::Vector3d::Zero();  // of |f - f_true| / f_true, per channel
  Eigen::Vector3d p95 = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  // mean of (f - f_true) / f_true: a scale error shows here
};

struct ThetaBand {
  double low_deg = 0.0, high_deg = 0.0;
  ErrorStats stats;
};

struct TruthComparison {
  bool success = false;
  ErrorStats overall;
  std::vector<ThetaBand> bands;
  size_t skipped_zero_truth = 0;  // samples where the true BRDF is 0 (no relative error defined)
  std::string BriefReport() const;
};

// Band edges in degrees; the default splits 0-20-40-60-70-80-90.
TruthComparison CompareWithTruth(const std::vector<BrdfSample>& samples, const BrdfModel& truth,
                                 const std::vector<double>& band_edges_deg = {0, 20, 40, 60, 70, 80, 90});

// CompareWithTruth of a sample file's samples, read a chunk at a time (ForEachSampleChunk) rather than
// whole: the same figures, bit for bit; the memory is the relative errors kept for the percentiles
// (3 doubles a sample, twice), not the 76-byte rows. Throws Error as ReadSamples does.
TruthComparison CompareSampleFileWithTruth(const std::string& samples_path, const BrdfModel& truth,
                                           const std::vector<double>& band_edges_deg = {0, 20, 40, 60, 70, 80, 90});

nlohmann::json ToJson(const TruthComparison& comparison);

// Reads the material of a synthetic session's truth.json ({"format": "ibrdf-truth", "version": 1, ...},
// written by synth/synthetic.cc). Throws Error naming the file and field for another format or an
// unknown version, and (core/truth_file.h's kSpatiallyVaryingTruth, naming "material_map") for a
// truth.json with a material map in place of a material: its per-point truth is synth/material_map.h's.
std::unique_ptr<BrdfModel> LoadTruthMaterial(const std::string& truth_path);
// Any truth: truth.json (as LoadTruthMaterial), a plain material file, or a MERL table (".binary").
std::unique_ptr<BrdfModel> LoadTruthFile(const std::string& path);

// truth.json beside the session the samples came from, as the samples' sidecar records it. Throws Error
// (suggesting --truth) when there is no sidecar, it names no session, or the session has no truth.json.
std::string TruthPathFromSidecar(const std::string& samples_path);

// The comparison as the table `ibrdf compare` prints: median and 95th-percentile relative error per
// channel (percent) for each non-empty band and overall, one line each.
std::string ComparisonTable(const TruthComparison& comparison);

// What `ibrdf compare` finds for `input`: a sample file against the truth (CompareWithTruth), or a MERL
// table's lookups at `lookups` random direction pairs (CheckMerlLookups).
struct CompareOutcome {
  nlohmann::json json;  // the figures, with "samples" (or "table") and "truth": the paths compared
  std::string text;     // what the command prints: the comparison table, or the lookup check's line
  std::string brief;    // the comparison's BriefReport ("" for a table)
};

// `truth_path`: truth.json, a material file or a MERL table (LoadTruthFile).
CompareOutcome CompareFileWithTruth(const std::string& input, const std::string& truth_path, size_t lookups);

}  // namespace ibrdf
