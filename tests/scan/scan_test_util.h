// Helpers shared by the scan/ tests: the bunny data folder, angles, medians, small files.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

namespace ibrdf::testing {

inline std::string BunnyDir() { return std::string(IBRDF_SHARED_DATA_DIR) + "/bunny-range-scans"; }
inline bool HaveBunny() { return std::filesystem::exists(BunnyDir() + "/bun000.ply"); }
#define IBRDF_REQUIRE_BUNNY()                                                                  \
  if (!::ibrdf::testing::HaveBunny())                                                          \
  GTEST_SKIP() << "the Stanford bunny range scans are not in " << ::ibrdf::testing::BunnyDir() \
               << " (../shared/data is absent in a fresh clone)"

// Angle between two directions in radians, accurate for tiny angles (atan2 of cross and dot).
inline double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace ibrdf::testing
