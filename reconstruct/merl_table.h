// Tabulation of a local regression to the MERL format (core/merl_format.h describes the file): every
// cell centre evaluated, classified measured / interpolated / unmeasured by where the samples are
// (reconstruct/sample_domain.h), unmeasured cells written as -1 or filled on request.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/brdf_model.h"
#include "core/merl_format.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/sample_domain.h"

namespace ibrdf {

struct TabulateOptions {
  double max_theta_deg = 90.0;         // cells with theta_i or theta_e beyond this are not tabulated (-1)
  float min_effective_samples = 0.0f;  // cells whose estimate has fewer are unmeasured
  DomainRules domain;                  // measured / interpolated / unmeasured (reconstruct/sample_domain.h)
  FillMode fill = FillMode::kNone;     // what unmeasured cells hold (kModel needs a model to fill with)
  bool Check(std::string* why) const;
};

struct TabulateSummary {
  bool success = false;
  ReliabilityCounts reliability;                        // of the evaluated cells
  DomainCounts domain;                                  // cells within the theta limit, by class (and filled)
  uint64_t cells_below_horizon = 0;                     // beyond max_theta_deg (or the horizon): always -1
  uint64_t evaluations = 0;                             // distinct regression evaluations (bilateral mirrors share one)
  double theta_d_min_deg = 0.0, theta_d_max_deg = 0.0;  // the samples' theta_d range
  FillMode fill = FillMode::kNone;
  std::string fill_model;  // the model that filled unmeasured cells (kModel)
  double seconds = 0.0;
  std::string BriefReport() const;
};

// Evaluates the regression at every cell centre of the MERL grid (TBB-parallel, with a progress bar and
// a time estimate). With bilateral folding, cells k and 179 - k share one evaluation. Each cell within
// the theta limit is classified (ClassifyEstimate); measured and interpolated cells get the estimate,
// unmeasured ones -1, or with options.fill the regression's estimate (kExtrapolate, where it has one)
// or `fill_model` (kModel; required then). `effective_samples` (optional) gets each cell's effective
// sample count (kMerlCells floats, 0 where unmeasured); `domain` (optional) each cell's DomainClass
// (kMerlCells bytes, 0 beyond the theta limit); `uncertainty` (optional) each cell's standard error per
// channel (3 kMerlCells floats, Estimate::standard_error, relative) where the cell holds the
// regression's estimate, -1 where it holds no value or a model's. Throws Error on bad options.
MerlTable TabulateMerl(const LocalRegression& regression, const TabulateOptions& options, TabulateSummary* summary,
                       std::vector<float>* effective_samples = nullptr, std::vector<uint8_t>* domain = nullptr,
                       const BrdfModel* fill_model = nullptr, std::vector<float>* uncertainty = nullptr);

// The table as a float64 array of shape (90, 90, 180, 3) in 1/sr (-1 where unmeasured), for .npy.
std::vector<double> MerlToArray(const MerlTable& table);

}  // namespace ibrdf
