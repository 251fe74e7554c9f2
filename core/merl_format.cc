#include "core/merl_format.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {

const double kMerlScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

// The three coordinate functions follow BRDFRead.cpp line by line (including its arithmetic order), so a
// direction lands in the same cell as in the reader.
double MerlThetaHalfCoordinate(double theta_h) {
  if (theta_h <= 0.0) return 0.0;
  const double theta_half_deg = (theta_h / (M_PI / 2.0)) * kMerlThetaH;
  return std::sqrt(theta_half_deg * kMerlThetaH);
}

double MerlThetaDiffCoordinate(double theta_d) { return theta_d / (M_PI * 0.5) * kMerlThetaD; }

double MerlPhiDiffCoordinate(double phi_d) {
  if (phi_d < 0.0) phi_d += M_PI;
  return phi_d / M_PI * (2 * kMerlPhiD) / 2;
}

namespace {
// The reader's truncation of a coordinate, clamped to [0, cells - 1].
int ClampedIndex(double coordinate, int cells) {
  const int index = static_cast<int>(coordinate);
  if (index < 0) return 0;
  if (index < cells - 1) return index;
  return cells - 1;
}
}  // namespace

int MerlThetaHalfIndex(double theta_h) { return ClampedIndex(MerlThetaHalfCoordinate(theta_h), kMerlThetaH); }

int MerlThetaDiffIndex(double theta_d) { return ClampedIndex(MerlThetaDiffCoordinate(theta_d), kMerlThetaD); }

int MerlPhiDiffIndex(double phi_d) { return ClampedIndex(MerlPhiDiffCoordinate(phi_d), kMerlPhiD); }

HalfDiffAngles MerlCellCentre(int i, int j, int k) {
  HalfDiffAngles angles;
  const double t = (i + 0.5) / kMerlThetaH;
  angles.theta_h = t * t * (M_PI / 2.0);
  angles.phi_h = 0.0;
  angles.theta_d = (j + 0.5) / kMerlThetaD * (M_PI / 2.0);
  angles.phi_d = (k + 0.5) / kMerlPhiD * M_PI;
  return angles;
}

Eigen::Vector3d MerlTable::Cell(size_t flat) const {
  return {stored_[flat] * kMerlScale[0], stored_[flat + kMerlCells] * kMerlScale[1],
          stored_[flat + 2 * kMerlCells] * kMerlScale[2]};
}

void MerlTable::SetCell(size_t flat, const Eigen::Vector3d& brdf) {
  for (int c = 0; c < 3; ++c) stored_[flat + c * kMerlCells] = brdf[c] / kMerlScale[c];
}

void MerlTable::SetUnmeasured(size_t flat) {
  for (int c = 0; c < 3; ++c) stored_[flat + c * kMerlCells] = -1.0;
}

Eigen::Vector3d MerlTable::Lookup(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const {
  HalfDiffAngles angles;
  ToHalfDiff(wi, wo, &angles);
  return Cell(MerlFlatIndex(MerlThetaHalfIndex(angles.theta_h), MerlThetaDiffIndex(angles.theta_d),
                            MerlPhiDiffIndex(angles.phi_d)));
}

void WriteMerl(const std::string& path, const MerlTable& table) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temporary_path(), std::ios::binary);
    if (!out) ThrowError(path, "cannot write file");
    const int32_t dims[3] = {kMerlThetaH, kMerlThetaD, kMerlPhiD};
    out.write(reinterpret_cast<const char*>(dims), sizeof(dims));
    out.write(reinterpret_cast<const char*>(table.stored().data()),
              static_cast<std::streamsize>(table.stored().size() * sizeof(double)));
    if (!out) ThrowError(path, "write failed (disk full?)");
  }
  file.Commit();
}

MerlTable ReadMerl(const std::string& path) {
  RequireFile(path, "MERL BRDF file");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  in.seekg(0);
  int32_t dims[3] = {0, 0, 0};
  if (!in.read(reinterpret_cast<char*>(dims), sizeof(dims))) ThrowError(path, "too short for a MERL header");
  if (dims[0] != kMerlThetaH || dims[1] != kMerlThetaD || dims[2] != kMerlPhiD) {
    ThrowError(path, "dimensions " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                         std::to_string(dims[2]) + ", expected 90 x 90 x 180 (a MERL .binary file)");
  }
  const std::streamoff expected = static_cast<std::streamoff>(sizeof(dims) + 3 * kMerlCells * sizeof(double));
  if (size != expected) {
    ThrowError(path, "size " + std::to_string(size) + " bytes, expected " + std::to_string(expected));
  }
  MerlTable table;
  in.read(reinterpret_cast<char*>(table.stored().data()),
          static_cast<std::streamsize>(3 * kMerlCells * sizeof(double)));
  if (!in) ThrowError(path, "read failed");
  // A BRDF over 1e10 per steradian reflects no real surface; such values (a damaged or foreign file)
  // overflow the lookups' weighted sums into inf and NaN.
  constexpr double kMaxBrdf = 1e10;
  static const char* const kChannel[3] = {"red", "green", "blue"};
  for (size_t i = 0; i < table.stored().size(); ++i) {
    const double stored = table.stored()[i];
    if (!std::isfinite(stored)) ThrowError(path, "value " + std::to_string(i) + " is not finite");
    const size_t channel = i / kMerlCells;
    if (std::abs(stored * kMerlScale[channel]) > kMaxBrdf) {
      std::ostringstream value;
      value << stored;
      ThrowError(path, "value " + std::to_string(i) + " (" + kChannel[channel] + ", cell " +
                           std::to_string(i % kMerlCells) + ") is " + value.str() +
                           ": no BRDF value (at most 1e10 per steradian; negative marks an unmeasured cell)");
    }
  }
  return table;
}

}  // namespace ibrdf
