#include "reconstruct/sample_domain.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/kind.h"

namespace ibrdf {

const char* DomainClassName(DomainClass c) {
  switch (c) {
    case DomainClass::kMeasured:
      return "measured";
    case DomainClass::kInterpolated:
      return "interpolated";
    case DomainClass::kUnmeasured:
      return "unmeasured";
  }
  UnhandledKind("DomainClass", static_cast<int>(c));
}

bool DomainRules::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(measured_nearest, 0.0);
  IBRDF_CHECK_OPTION_GT(max_centroid_offset, 0.0);
  IBRDF_CHECK_OPTION_GE(theta_d_margin_deg, 0.0);
  IBRDF_CHECK_OPTION_GT(max_measured_standard_error, 0.0);
  return true;
}

DomainClass ClassifyEstimate(const Estimate& e, double theta_d, const LocalRegression& regression,
                             const DomainRules& rules) {
  if (e.status == EstimateStatus::kUnsupported) return DomainClass::kUnmeasured;
  const double margin = rules.theta_d_margin_deg * M_PI / 180.0;
  if (theta_d < regression.theta_d_min() - margin || theta_d > regression.theta_d_max() + margin) {
    return DomainClass::kUnmeasured;
  }
  if (!(e.centroid_offset <= rules.max_centroid_offset)) return DomainClass::kUnmeasured;
  if (e.status != EstimateStatus::kGrown && e.nearest <= rules.measured_nearest &&
      e.standard_error.maxCoeff() <= rules.max_measured_standard_error) {
    return DomainClass::kMeasured;
  }
  return DomainClass::kInterpolated;
}

const char* FillModeName(FillMode mode) {
  switch (mode) {
    case FillMode::kModel:
      return "model";
    case FillMode::kExtrapolate:
      return "extrapolate";
    case FillMode::kNone:
      return "none";
  }
  UnhandledKind("FillMode", static_cast<int>(mode));
}

bool ParseFillMode(const std::string& text, FillMode* mode) {
  for (FillMode m : {FillMode::kNone, FillMode::kModel, FillMode::kExtrapolate}) {
    if (text == FillModeName(m)) {
      *mode = m;
      return true;
    }
  }
  return false;
}

void DomainCounts::Add(DomainClass c) {
  switch (c) {
    case DomainClass::kMeasured:
      ++measured;
      break;
    case DomainClass::kInterpolated:
      ++interpolated;
      break;
    case DomainClass::kUnmeasured:
      ++unmeasured;
      break;
  }
}

void DomainCounts::Merge(const DomainCounts& other) {
  measured += other.measured;
  interpolated += other.interpolated;
  unmeasured += other.unmeasured;
  filled += other.filled;
}

std::string DomainCounts::Brief() const {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), "%llu measured, %llu interpolated, %llu unmeasured (%llu filled)",
                (unsigned long long)measured, (unsigned long long)interpolated, (unsigned long long)unmeasured,
                (unsigned long long)filled);
  return buffer;
}

nlohmann::json ToJson(const DomainCounts& counts) {
  return {{"measured", counts.measured},
          {"interpolated", counts.interpolated},
          {"unmeasured", counts.unmeasured},
          {"unmeasured_filled", counts.filled}};
}

}  // namespace ibrdf
