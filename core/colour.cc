#include "core/colour.h"

#include <cmath>

#include <Eigen/LU>

namespace ibrdf {
namespace {

// X-Rite ColorChecker Classic, November 2014 edition and newer: CIELab, D50, 2 degree observer.
constexpr double kLabD50[kColorCheckerPatches][3] = {
    {37.54, 14.37, 14.92},  {64.66, 19.27, 17.50},   {49.32, -3.82, -22.54}, {43.46, -12.74, 22.72},
    {54.94, 9.61, -24.79},  {70.48, -32.26, -0.37},  {62.73, 35.83, 56.50},  {39.43, 10.75, -45.17},
    {50.57, 48.64, 16.67},  {30.10, 22.54, -20.87},  {71.77, -24.13, 58.19}, {71.51, 18.24, 67.37},
    {28.37, 15.42, -49.80}, {54.38, -39.72, 32.27},  {42.43, 51.05, 28.62},  {81.80, 2.67, 80.41},
    {50.63, 51.28, -14.12}, {49.57, -29.71, -28.32}, {95.19, -1.03, 2.93},   {81.29, -0.57, 0.44},
    {66.89, -0.75, -0.06},  {50.76, -0.13, 0.14},    {35.63, -0.46, -0.48},  {20.64, 0.07, -0.46},
};

const Eigen::Vector3d kWhiteD50(0.96422, 1.0, 0.82521);
const Eigen::Vector3d kWhiteD65(0.95047, 1.0, 1.08883);

// CIELab's inverse companding.
double LabInverse(double t) {
  constexpr double kDelta = 6.0 / 29.0;
  return t > kDelta ? t * t * t : 3.0 * kDelta * kDelta * (t - 4.0 / 29.0);
}

// Bradford chromatic adaptation from D50 to D65 (von Kries scaling in the Bradford cone space).
Eigen::Matrix3d BradfordD65FromD50() {
  Eigen::Matrix3d cone;
  cone << 0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296;
  const Eigen::Vector3d scale = (cone * kWhiteD65).cwiseQuotient(cone * kWhiteD50);
  return cone.inverse() * scale.asDiagonal() * cone;
}

}  // namespace

const char* ColourSpaceName(ColourSpace space) {
  switch (space) {
    case ColourSpace::kLinearSrgb:
      return "linear_srgb";
    case ColourSpace::kXyz:
      return "xyz";
  }
  UnhandledKind("ColourSpace", static_cast<int>(space));
}

const char* ColourSpaceLabel(ColourSpace space) {
  switch (space) {
    case ColourSpace::kLinearSrgb:
      return "linear sRGB (D65)";
    case ColourSpace::kXyz:
      return "CIE XYZ (D65)";
  }
  UnhandledKind("ColourSpace", static_cast<int>(space));
}

Eigen::Matrix3d LinearSrgbFromSpace(ColourSpace space, const Eigen::Matrix3d& m) {
  switch (space) {
    case ColourSpace::kLinearSrgb:
      return m;
    case ColourSpace::kXyz:
      return LinearSrgbFromXyz() * m;
  }
  UnhandledKind("ColourSpace", static_cast<int>(space));
}

Eigen::Matrix3d SpaceFromLinearSrgb(ColourSpace space, const Eigen::Matrix3d& m) {
  switch (space) {
    case ColourSpace::kLinearSrgb:
      return m;
    case ColourSpace::kXyz:
      return XyzFromLinearSrgb() * m;
  }
  UnhandledKind("ColourSpace", static_cast<int>(space));
}

bool ColourSpaceFromName(const std::string& name, ColourSpace* space) {
  for (ColourSpace s : {ColourSpace::kLinearSrgb, ColourSpace::kXyz}) {
    if (name == ColourSpaceName(s)) {
      *space = s;
      return true;
    }
  }
  return false;
}

Eigen::Matrix3d LinearSrgbFromXyz() {
  Eigen::Matrix3d m;
  m << 3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108, 0.0415560, 0.0556434, -0.2040259, 1.0572252;
  return m;
}

Eigen::Matrix3d XyzFromLinearSrgb() { return LinearSrgbFromXyz().inverse(); }

const std::array<const char*, kColorCheckerPatches>& ColorCheckerPatchNames() {
  static const std::array<const char*, kColorCheckerPatches> kNames = {
      "dark skin", "light skin",    "blue sky",     "foliage",   "blue flower",  "bluish green",
      "orange",    "purplish blue", "moderate red", "purple",    "yellow green", "orange yellow",
      "blue",      "green",         "red",          "yellow",    "magenta",      "cyan",
      "white 9.5", "neutral 8",     "neutral 6.5",  "neutral 5", "neutral 3.5",  "black 2"};
  return kNames;
}

std::array<Eigen::Vector3d, kColorCheckerPatches> ColorCheckerReference(ColourSpace space) {
  const Eigen::Matrix3d adapt = BradfordD65FromD50();
  std::array<Eigen::Vector3d, kColorCheckerPatches> values;
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    const double fy = (kLabD50[k][0] + 16.0) / 116.0;
    const double fx = fy + kLabD50[k][1] / 500.0;
    const double fz = fy - kLabD50[k][2] / 200.0;
    const Eigen::Vector3d xyz_d50 =
        Eigen::Vector3d(LabInverse(fx), LabInverse(fy), LabInverse(fz)).cwiseProduct(kWhiteD50);
    const Eigen::Vector3d xyz_d65 = adapt * xyz_d50;
    values[k] = xyz_d65;
    switch (space) {
      case ColourSpace::kLinearSrgb:
        values[k] = LinearSrgbFromXyz() * xyz_d65;
        break;
      case ColourSpace::kXyz:
        break;
    }
  }
  return values;
}

const char* ColorCheckerReferenceSource() {
  return "X-Rite ColorChecker Classic, November 2014 edition and newer: CIELab (D50, 2 deg), to XYZ D50, "
         "Bradford-adapted to D65, to the target space (linear sRGB: IEC 61966-2-1)";
}

}  // namespace ibrdf
