// A MERL table with holes, shared by synth's MERL tests (library and command line).
#pragma once

#include <string>

#include <Eigen/Core>

#include "core/merl_format.h"
#include "tests/scratch_dir.h"

namespace ibrdf::testing {

// Writes `dir`/holey.binary, a table with data (0.1, 0.2, 0.3) only below theta_d 30 degrees (every cell
// beyond is without data), and returns its path.
inline std::string HoleyMerlTable(const ScratchDir& dir) {
  MerlTable table;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < 30; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) table.SetCell(MerlFlatIndex(i, j, k), Eigen::Vector3d(0.1, 0.2, 0.3));
    }
  }
  WriteMerl(dir / "holey.binary", table);
  return dir / "holey.binary";
}

}  // namespace ibrdf::testing
