#include "core/merl_brdf.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/kind.h"

namespace ibrdf {

const char* MerlLookupName(MerlLookup lookup) {
  switch (lookup) {
    case MerlLookup::kNearest:
      return "nearest";
    case MerlLookup::kLinear:
      return "linear";
  }
  UnhandledKind("MerlLookup", static_cast<int>(lookup));
}

MerlLookup MerlLookupFromName(const std::string& name, const std::string& where) {
  if (name == "nearest") return MerlLookup::kNearest;
  if (name == "linear") return MerlLookup::kLinear;
  ThrowError(where, "unknown MERL lookup \"" + name + "\" (expected nearest or linear)");
}

MerlBrdf::MerlBrdf(const std::string& path, MerlLookup lookup) : MerlBrdf(ReadMerl(path), path, lookup) {}

namespace {
// A continuous index coordinate `u` (cell c spans [c, c + 1), its centre at c + 0.5) as the two
// neighbouring cells and the second one's weight: clamped to the first and last centres of n cells,
// or (periodic) wrapped around them.
void Neighbours(double u, int n, bool periodic, int* c0, int* c1, double* t) {
  const double x = u - 0.5;
  double f = std::floor(x);
  *t = x - f;
  if (periodic) {
    const int k = static_cast<int>(f);
    *c0 = ((k % n) + n) % n;
    *c1 = (*c0 + 1) % n;
    return;
  }
  if (x <= 0.0) {
    *c0 = *c1 = 0;
    *t = 0.0;
  } else if (x >= n - 1) {
    *c0 = *c1 = n - 1;
    *t = 0.0;
  } else {
    *c0 = static_cast<int>(f);
    *c1 = *c0 + 1;
  }
}
}  // namespace

Eigen::Vector3d MerlBrdf::Lookup(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (lookup_ == MerlLookup::kNearest) return table_.Lookup(wi, wo);
  HalfDiffAngles angles;
  ToHalfDiff(wi, wo, &angles);
  // No data where the reader's own cell (the nearest lookup's) has none.
  const size_t cell = MerlFlatIndex(MerlThetaHalfIndex(angles.theta_h), MerlThetaDiffIndex(angles.theta_d),
                                    MerlPhiDiffIndex(angles.phi_d));
  if (!table_.Measured(cell)) return Eigen::Vector3d::Constant(-1.0);
  // The reader's index coordinates before truncation.
  const double u_h = MerlThetaHalfCoordinate(angles.theta_h);
  const double u_d = std::max(0.0, MerlThetaDiffCoordinate(angles.theta_d));
  const double u_p = MerlPhiDiffCoordinate(angles.phi_d);
  int h[2], d[2], p[2];
  double th, td, tp;
  Neighbours(u_h, kMerlThetaH, false, &h[0], &h[1], &th);
  Neighbours(u_d, kMerlThetaD, false, &d[0], &d[1], &td);
  Neighbours(u_p, kMerlPhiD, true, &p[0], &p[1], &tp);
  // The weights of the neighbours without data go to the others (the reader's cell always has data and
  // at least 1/8 of the weight): the table's edge is interpolated along it, never beyond it.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0.0;
  for (int a = 0; a < 2; ++a) {
    const double wa = a ? th : 1.0 - th;
    if (wa == 0.0) continue;
    for (int b = 0; b < 2; ++b) {
      const double wb = wa * (b ? td : 1.0 - td);
      if (wb == 0.0) continue;
      for (int c = 0; c < 2; ++c) {
        const double w = wb * (c ? tp : 1.0 - tp);
        if (w == 0.0) continue;
        const size_t flat = MerlFlatIndex(h[a], d[b], p[c]);
        if (!table_.Measured(flat)) continue;
        sum += w * table_.Cell(flat);
        weight += w;
      }
    }
  }
  return sum / weight;
}

MerlBrdf::MerlBrdf(MerlTable table, std::string path, MerlLookup lookup)
    : table_(std::move(table)), path_(std::filesystem::absolute(path).lexically_normal().string()), lookup_(lookup) {
  for (size_t flat = 0; flat < kMerlCells; ++flat) cells_without_data_ += !table_.Measured(flat);
}

Eigen::Vector3d MerlBrdf::Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  if (!(wi.z() > 0.0 && wo.z() > 0.0)) return Eigen::Vector3d::Zero();
  lookups_.fetch_add(1, std::memory_order_relaxed);
  const Eigen::Vector3d f = Lookup(wi.normalized(), wo.normalized());
  if ((f.array() < 0.0).any()) {
    no_data_lookups_.fetch_add(1, std::memory_order_relaxed);
    return Eigen::Vector3d::Zero();
  }
  return f;
}

nlohmann::json MerlBrdf::ToJson() const {
  nlohmann::json json = {{"model", "merl"}, {"file", path_}};
  if (lookup_ != MerlLookup::kNearest) json["lookup"] = MerlLookupName(lookup_);
  return json;
}

bool IsMerlPath(const std::string& path) { return std::filesystem::path(path).extension() == ".binary"; }

}  // namespace ibrdf
