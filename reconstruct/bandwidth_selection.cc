#include "reconstruct/bandwidth_selection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/kind.h"
#include "core/logging.h"

namespace ibrdf {

bool ParseBandwidthCriterion(const std::string& name, BandwidthCriterion* criterion) {
  if (name == "loo") {
    *criterion = BandwidthCriterion::kLeaveOneOut;
  } else if (name == "gcv") {
    *criterion = BandwidthCriterion::kGeneralizedCrossValidation;
  } else {
    return false;
  }
  return true;
}

const char* BandwidthCriterionName(BandwidthCriterion criterion) {
  switch (criterion) {
    case BandwidthCriterion::kLeaveOneOut:
      return "loo";
    case BandwidthCriterion::kGeneralizedCrossValidation:
      return "gcv";
  }
  UnhandledKind("BandwidthCriterion", static_cast<int>(criterion));
}

bool BandwidthSelectionOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!scales.empty());
  for (const double scale : scales) {
    IBRDF_CHECK_OPTION_GT(scale, 0.0);
    IBRDF_CHECK_OPTION_LE(scale, 100.0);
  }
  IBRDF_CHECK_OPTION_GE(samples, size_t(10));
  return true;
}

std::string BandwidthSelection::BriefReport() const {
  if (!success) return "bandwidth selection did not run";
  const BandwidthCandidate& b = curve[best];
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "bandwidth by %s: scale %.2f, radii %.2f x %.2f deg (criterion %.4f, %zu candidates, %zu samples "
                "each, %.1f s)",
                BandwidthCriterionName(criterion), b.scale, b.radius_h_deg, b.radius_d_deg, b.criterion, curve.size(),
                b.score.points, seconds);
  return buffer;
}

std::string BandwidthSelection::CurveTable() const {
  std::string table = "  scale  radius_h  radius_d   loo_rms  resid_rms  leverage   gcv_rms\n";
  for (size_t i = 0; i < curve.size(); ++i) {
    const BandwidthCandidate& c = curve[i];
    char line[160];
    std::snprintf(line, sizeof(line), "  %5.2f  %8.2f  %8.2f  %8.5f  %9.5f  %8.5f  %8.5f%s\n", c.scale, c.radius_h_deg,
                  c.radius_d_deg, c.score.loo_rms, c.score.residual_rms, c.score.mean_leverage, c.score.gcv_rms,
                  i == best ? "  <- selected" : "");
    table += line;
  }
  return table;
}

BandwidthSelection SelectBandwidth(const std::vector<BrdfSample>& samples, const LocalRegressionOptions& base,
                                   const BandwidthSelectionOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("bandwidth selection options", why);
  if (!base.Check(&why)) ThrowError("local regression options", why);
  Timer timer;
  BandwidthSelection selection;
  selection.criterion = options.criterion;
  double best = std::numeric_limits<double>::infinity();
  for (double scale : options.scales) {
    BandwidthCandidate candidate;
    candidate.scale = scale;
    LocalRegressionOptions trial = base;
    trial.radius_h_deg = candidate.radius_h_deg = std::min(90.0, base.radius_h_deg * scale);
    trial.radius_d_deg = candidate.radius_d_deg = std::min(90.0, base.radius_d_deg * scale);
    const LocalRegression regression(samples, trial);
    candidate.score = regression.CrossValidate(options.samples, options.seed);
    candidate.criterion =
        options.criterion == BandwidthCriterion::kLeaveOneOut ? candidate.score.loo_rms : candidate.score.gcv_rms;
    if (candidate.criterion < best) {
      best = candidate.criterion;
      selection.best = selection.curve.size();
      selection.selected = trial;
    }
    selection.curve.push_back(candidate);
  }
  selection.success = std::isfinite(best);
  if (!selection.success) selection.selected = base;
  selection.seconds = timer.ElapsedSeconds();
  return selection;
}

nlohmann::json ToJson(const BandwidthSelection& selection) {
  nlohmann::json curve = nlohmann::json::array();
  for (const BandwidthCandidate& c : selection.curve) {
    curve.push_back({{"scale", c.scale},
                     {"radius_h_deg", c.radius_h_deg},
                     {"radius_d_deg", c.radius_d_deg},
                     {"samples_scored", c.score.points},
                     {"loo_rms", c.score.loo_rms},
                     {"residual_rms", c.score.residual_rms},
                     {"mean_leverage", c.score.mean_leverage},
                     {"gcv_rms", c.score.gcv_rms}});
  }
  return {{"criterion", BandwidthCriterionName(selection.criterion)},
          {"success", selection.success},
          {"selected_radius_h_deg", selection.selected.radius_h_deg},
          {"selected_radius_d_deg", selection.selected.radius_d_deg},
          {"selected_index", selection.best},
          {"seconds", selection.seconds},
          {"curve", curve}};
}

}  // namespace ibrdf
