#include "core/radiometry.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"

namespace ibrdf {

double SrgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

double LinearToSrgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

double Response::ToLinear(double v) const {
  switch (kind) {
    case Kind::kLinear:
      return v;
    case Kind::kSrgb:
      return SrgbToLinear(v);
    case Kind::kGamma:
      return v <= 0.0 ? 0.0 : std::pow(v, gamma);
    case Kind::kTable: {
      const double x = std::clamp(v, 0.0, 1.0) * static_cast<double>(table.size() - 1);
      const size_t i = std::min(static_cast<size_t>(x), table.size() - 2);
      const double t = x - static_cast<double>(i);
      return table[i] + t * (table[i + 1] - table[i]);
    }
    case Kind::kUnknown:
      break;
  }
  IBRDF_CHECK(false) << "an unknown response read linearly";
  return v;
}

double Response::FromLinear(double v) const {
  switch (kind) {
    case Kind::kLinear:
      return v;
    case Kind::kSrgb:
      return LinearToSrgb(v);
    case Kind::kGamma:
      return v <= 0.0 ? 0.0 : std::pow(v, 1.0 / gamma);
    case Kind::kTable: {
      if (v <= table.front()) return 0.0;
      if (v >= table.back()) return 1.0;
      const size_t i = static_cast<size_t>(std::upper_bound(table.begin(), table.end(), v) - table.begin()) - 1;
      const double t = (v - table[i]) / (table[i + 1] - table[i]);
      return (static_cast<double>(i) + t) / static_cast<double>(table.size() - 1);
    }
    case Kind::kUnknown:
      break;
  }
  IBRDF_CHECK(false) << "an unknown response encoded";
  return v;
}

std::string Response::Describe() const {
  switch (kind) {
    case Kind::kLinear:
      return "linear";
    case Kind::kSrgb:
      return "srgb";
    case Kind::kGamma:
      return "gamma " + std::to_string(gamma);
    case Kind::kTable:
      return "table (" + std::to_string(table.size()) + " entries)";
    case Kind::kUnknown:
      return "unknown";
  }
  UnhandledKind("Response::Kind", static_cast<int>(kind));
}

bool Response::Check(std::string* why) const {
  if (kind == Kind::kGamma) {
    IBRDF_CHECK_OPTION_GT(gamma, 0.0);
    IBRDF_CHECK_OPTION(std::isfinite(gamma));
  }
  if (kind == Kind::kTable) {
    IBRDF_CHECK_OPTION_GE(table.size(), 2u);
    for (size_t i = 1; i < table.size(); ++i) {
      if (!(table[i] > table[i - 1])) {
        std::ostringstream message;
        message << "table must be strictly increasing: table[" << i << "] = " << table[i] << " after table[" << i - 1
                << "] = " << table[i - 1];
        *why = message.str();
        return false;
      }
    }
    if (!uncertainty.empty() && uncertainty.size() != table.size()) {
      *why = "uncertainty must have one entry per table entry (" + std::to_string(table.size()) + "), got " +
             std::to_string(uncertainty.size());
      return false;
    }
    for (double u : uncertainty) {
      if (!(u >= 0.0) || !std::isfinite(u)) {
        *why = "uncertainty entries must be finite and non-negative";
        return false;
      }
    }
  }
  return true;
}

}  // namespace ibrdf
