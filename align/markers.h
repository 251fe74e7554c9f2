// Coded targets: ArUco markers (OpenCV 4.6 contrib), their appearance for the synthetic renderer, and
// their detection with sub-pixel corners. OpenCV stays inside markers.cc.
//
// Corner order is OpenCV's: top-left, top-right, bottom-right, bottom-left of the marker as printed. In
// a marker's own frame the printed square lies in z = 0 with x to the right and y down the print, so
// the corners are (-s/2, -s/2), (s/2, -s/2), (s/2, s/2), (-s/2, s/2) and +z points into the print
// (away from a viewer who reads it).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/image_io.h"

namespace ibrdf {

// A predefined ArUco dictionary by OpenCV's name ("DICT_4X4_50", "DICT_5X5_100", ...).
class MarkerDictionary {
 public:
  // Throws Error (naming `where`) for an unknown dictionary name.
  explicit MarkerDictionary(const std::string& name, const std::string& where = "targets");
  const std::string& name() const { return name_; }
  int size() const { return size_; }         // number of marker ids
  int modules() const { return bits_ + 2; }  // cells across the printed marker, border included
  int id_for_opencv() const { return id_; }  // OpenCV's PREDEFINED_DICTIONARY_NAME value

  // The printed marker as modules() x modules() cells, row-major, true = white.
  std::vector<bool> Modules(int id) const;

 private:
  std::string name_;
  int id_ = 0;    // OpenCV's PREDEFINED_DICTIONARY_NAME
  int bits_ = 0;  // inner cells across
  int size_ = 0;
};

struct MarkerDetection {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners;  // pixels, COLMAP convention (pixel centres at +0.5)
};

struct MarkerDetectionOptions {
  bool subpixel = true;       // refine corners to sub-pixel accuracy
  double min_side_px = 12.0;  // detections with a shorter side are dropped
};

class Camera;

// Refines detected corners by edge fitting: sub-pixel edge points along each side of the marker's black
// square, a straight line fitted to each side in undistorted image-plane coordinates (so lens
// distortion does not bend it), and the corners as the intersections of adjacent lines. More accurate
// than OpenCV's corner refinement, which suits saddle points rather than a square's outer corners.
// A corner whose sides cannot be measured keeps its detected position.
void RefineMarkerCorners(const Image& image, const Camera& camera, std::vector<MarkerDetection>* detections);

// Detects markers in a photo (linear or encoded values in [0, 1]; converted to 8-bit grey with a
// display gamma so dark scenes still threshold well). Detections of ids the dictionary lacks cannot
// happen; duplicate ids in one photo are all returned (the caller decides).
std::vector<MarkerDetection> DetectMarkers(const Image& image, const MarkerDictionary& dictionary,
                                           const MarkerDetectionOptions& options = {});

}  // namespace ibrdf
