// The MERL BRDF database's binary format (Matusik et al. 2003, BRDFRead.cpp), bit-compatible with its
// reader: three int32 dimensions 90, 90, 180 (theta_h, theta_d, phi_d), then 90*90*180 doubles per
// channel, red, green, blue, each value stored as brdf / scale with RED_SCALE = 1/1500,
// GREEN_SCALE = 1.15/1500, BLUE_SCALE = 1.66/1500. The flat index is
// phi_d_index + 180 * (theta_d_index + 90 * theta_h_index). theta_h is indexed non-linearly,
// index = sqrt(theta_h / (pi/2)) * 90; theta_d and phi_d linearly, phi_d over [0, pi) (reciprocity
// folds phi_d + pi onto phi_d). Cells without a value (below the horizon, or no samples near them)
// hold -1, as the MERL data marks unmeasured cells with negative values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/brdf_coords.h"

namespace ibrdf {

constexpr int kMerlThetaH = 90;
constexpr int kMerlThetaD = 90;
constexpr int kMerlPhiD = 180;
constexpr size_t kMerlCells = size_t(kMerlThetaH) * kMerlThetaD * kMerlPhiD;
// The reader's per-channel scales: value = stored * scale.
extern const double kMerlScale[3];

// The reader's index coordinates before truncation (BRDFRead.cpp's arithmetic, in its order): cell i spans
// [i, i + 1), its centre at i + 0.5. theta_h <= 0 gives 0; phi_d < 0 is folded onto phi_d + pi. Not
// clamped: theta_d beyond pi/2 gives more than 90.
double MerlThetaHalfCoordinate(double theta_h);
double MerlThetaDiffCoordinate(double theta_d);
double MerlPhiDiffCoordinate(double phi_d);
// The reader's index functions: the coordinates above truncated and clamped to the table.
int MerlThetaHalfIndex(double theta_h);
int MerlThetaDiffIndex(double theta_d);
int MerlPhiDiffIndex(double phi_d);
inline size_t MerlFlatIndex(int i_theta_h, int i_theta_d, int i_phi_d) {
  return size_t(i_phi_d) + size_t(kMerlPhiD) * (size_t(i_theta_d) + size_t(kMerlThetaD) * size_t(i_theta_h));
}
// The centre of a cell in index space: theta_h = ((i + 0.5) / 90)^2 pi/2, theta_d = (j + 0.5) / 90 pi/2,
// phi_d = (k + 0.5) / 180 pi, phi_h = 0. The reader's index functions map it back to (i, j, k).
HalfDiffAngles MerlCellCentre(int i_theta_h, int i_theta_d, int i_phi_d);

// A MERL table in memory, holding exactly the stored doubles (brdf / scale, or -1).
class MerlTable {
 public:
  MerlTable() : stored_(3 * kMerlCells, -1.0) {}  // every cell unmeasured

  // The cell's RGB BRDF in 1/sr (stored * scale); negative when unmeasured.
  Eigen::Vector3d Cell(size_t flat) const;
  bool Measured(size_t flat) const {
    return stored_[flat] >= 0.0 && stored_[flat + kMerlCells] >= 0.0 && stored_[flat + 2 * kMerlCells] >= 0.0;
  }
  void SetCell(size_t flat, const Eigen::Vector3d& brdf);
  void SetUnmeasured(size_t flat);
  // As BRDFRead.cpp's lookup_brdf_val: the cell of (wi, wo) in the local frame; negative if unmeasured.
  Eigen::Vector3d Lookup(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) const;

  const std::vector<double>& stored() const { return stored_; }
  std::vector<double>& stored() { return stored_; }

 private:
  std::vector<double> stored_;  // 3 * kMerlCells, channel-major as in the file
};

// Writes the binary file atomically; reads one back, checking the dimensions and the size (Error naming
// the file otherwise).
void WriteMerl(const std::string& path, const MerlTable& table);
MerlTable ReadMerl(const std::string& path);

}  // namespace ibrdf
