// Colour vocabulary: the target spaces of a colour correction and the published reference values of
// the X-Rite ColorChecker Classic (24 patches), converted to them. The correction itself (measuring
// a chart photo, fitting camera RGB to the reference) is calibrate/colour_chart.h; docs/radiometry.md,
// "Colour".
#pragma once

#include <array>
#include <string>

#include <Eigen/Core>

#include "core/kind.h"

namespace ibrdf {

// The space a colour correction maps camera RGB into.
enum class ColourSpace {
  kLinearSrgb,  // linear sRGB (IEC 61966-2-1 primaries, D65 white), no transfer curve
  kXyz,         // CIE 1931 XYZ, D65 white (Y = 1 for a perfect white diffuser)
  IBRDF_DUMMY_KIND
};

// "linear_srgb", "xyz"; and back (false for any other name).
const char* ColourSpaceName(ColourSpace space);
bool ColourSpaceFromName(const std::string& name, ColourSpace* space);
// "linear sRGB (D65)", "CIE XYZ (D65)": the space's name for people.
const char* ColourSpaceLabel(ColourSpace space);
// `m`, a matrix into `space`, made a matrix into linear sRGB (`m` itself for linear sRGB); and a matrix
// into linear sRGB made one into `space`.
Eigen::Matrix3d LinearSrgbFromSpace(ColourSpace space, const Eigen::Matrix3d& m);
Eigen::Matrix3d SpaceFromLinearSrgb(ColourSpace space, const Eigen::Matrix3d& m);

// The chart types a session's colour_chart block may name. Only the ColorChecker Classic 24 for now
// (also its Mini and Nano editions: the same patches, smaller).
constexpr char kColorCheckerClassic24[] = "colorchecker_classic_24";
constexpr int kColorCheckerPatches = 24;
constexpr int kColorCheckerColumns = 6;  // patch 1 (dark skin) top left, 6 (bluish green) top right,
constexpr int kColorCheckerRows = 4;     // 19 (white) bottom left, 24 (black) bottom right

// XYZ (D65) from linear sRGB, and back (IEC 61966-2-1).
Eigen::Matrix3d XyzFromLinearSrgb();
Eigen::Matrix3d LinearSrgbFromXyz();

// The 24 patches' names in chart order ("dark skin", ..., "black"), row-major from the top left.
const std::array<const char*, kColorCheckerPatches>& ColorCheckerPatchNames();

// The ColorChecker Classic's published reference values in `space`: X-Rite's CIELab (D50, 2 degree
// observer) of the November 2014 edition and newer, converted to XYZ (D50), adapted to D65 with the
// Bradford transform and, for linear sRGB, converted with the IEC 61966-2-1 matrix. Patch 18 (cyan)
// lies outside the sRGB gamut: its linear-sRGB red is -0.044. Values are reflectances: a perfect
// white diffuser would read (1, 1, 1) in linear sRGB, (0.9505, 1, 1.0888) in XYZ.
std::array<Eigen::Vector3d, kColorCheckerPatches> ColorCheckerReference(ColourSpace space);
// What ColorCheckerReference states about its source, for sidecars and logs.
const char* ColorCheckerReferenceSource();

}  // namespace ibrdf
