// A BRDF tabulated in a MERL file (core/merl_format.h) as a material: `ibrdf synth --material X.binary`
// renders it, `compare` and `reconstruct --truth` score against it. Lookups are the MERL reader's
// (BRDFRead.cpp lookup_brdf_val): the cell holding (theta_h, theta_d, phi_d), no interpolation. A cell
// holding a negative value ("no data") evaluates to 0 and is counted (no_data_lookups), so a caller
// can report how much of what it rendered or compared came from cells without data.
//
// MerlLookup::kLinear (`synth --merl-lookup linear`) interpolates instead: trilinear between the eight
// cell centres around the point in the table's own index coordinates (sqrt(theta_h) for theta_h,
// phi_d periodic over its 180 degrees, clamped beyond the first and last centres of theta_h and
// theta_d), so at a cell centre it returns the cell. A point is a no-data lookup exactly where the
// nearest lookup is one (its own cell has no data); neighbours without data are left out of the
// interpolation and its weights renormalized over the others (no value beyond the table's data).
//
// In material files: {"model": "merl", "file": "brdf.binary"} (a relative path is taken from the
// material file's folder), with "lookup": "linear" for kLinear; ToJson writes the absolute path.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "core/brdf_model.h"
#include "core/merl_format.h"

namespace ibrdf {

// How a MerlBrdf looks a direction pair up: the MERL reader's nearest cell, or trilinear.
enum class MerlLookup { kNearest, kLinear };

// "nearest", "linear"; and back (throws Error naming `where` and the value otherwise).
const char* MerlLookupName(MerlLookup lookup);
MerlLookup MerlLookupFromName(const std::string& name, const std::string& where);

class MerlBrdf : public BrdfModel {
 public:
  // Reads `path` (Error naming the file when it is not a MERL table).
  explicit MerlBrdf(const std::string& path, MerlLookup lookup = MerlLookup::kNearest);
  MerlBrdf(MerlTable table, std::string path, MerlLookup lookup = MerlLookup::kNearest);
  Eigen::Vector3d Eval(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const override;
  nlohmann::json ToJson() const override;
  std::string ModelName() const override { return "merl"; }

  const MerlTable& table() const { return table_; }
  MerlLookup lookup() const { return lookup_; }
  // The table at (wi, wo), both above the horizon, as this lookup reads it: negative in every channel
  // where it has no data (no counting; Eval returns 0 there and counts).
  Eigen::Vector3d Lookup(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const;
  const std::string& path() const { return path_; }
  uint64_t cells_without_data() const { return cells_without_data_; }  // cells with a negative channel
  // Evaluations above the horizon that hit a cell without data (returned as 0), and all of them.
  uint64_t no_data_lookups() const { return no_data_lookups_.load(); }
  uint64_t lookups() const { return lookups_.load(); }

 private:
  MerlTable table_;
  std::string path_;
  MerlLookup lookup_ = MerlLookup::kNearest;
  uint64_t cells_without_data_ = 0;
  mutable std::atomic<uint64_t> no_data_lookups_{0}, lookups_{0};
};

// True when `path` names a MERL table (by its ".binary" extension).
bool IsMerlPath(const std::string& path);

}  // namespace ibrdf
