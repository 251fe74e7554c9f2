// Camera intrinsics from photos of a ChArUco board: ArUco markers in the white
// squares of a chessboard identify the chessboard's inner corners, which are located at sub-pixel
// precision (saddle points) and fed to OpenCV's calibration (Zhang's method with Levenberg-Marquardt
// refinement) for the OPENCV model: fx, fy, cx, cy, k1, k2, p1, p2 (k3 fixed at 0, as COLMAP's OPENCV
// model has none). OpenCV puts the first pixel's centre at (0, 0), COLMAP and ibrdf at (0.5, 0.5): the
// principal point is converted. OpenCV stays inside the .cc file.
//
// The board folder holds the photos (any format ibrdf reads) and board.json:
//   {"format": "ibrdf-charuco-board", "version": 1, "dictionary": "DICT_5X5_100",
//    "squares_x": 9, "squares_y": 7, "square_size": 0.025, "marker_size": 0.018}
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/camera.h"

namespace ibrdf {

// A ChArUco board as OpenCV 4.6 contrib lays it out (cv::aruco::CharucoBoard::create): squares_x by
// squares_y chessboard squares, the markers (ids 0, 1, ...) in the white squares. The number of rows
// must be odd: with an even number, boards printed by other OpenCV versions differ in which squares are
// black, and OpenCV 4.6 would read them wrongly.
struct CharucoBoardSpec {
  std::string dictionary = "DICT_5X5_100";  // OpenCV predefined dictionary
  int squares_x = 9;                        // squares across
  int squares_y = 7;                        // squares down; odd
  double square_size = 0.025;               // metres, side of a chessboard square
  double marker_size = 0.018;               // metres, side of a marker (border included), < square_size

  bool Check(std::string* why) const;
  // The inner chessboard corners, the calibration points, by ChArUco corner id, in the board frame:
  // OpenCV's, metres, z = 0, origin at the printed board's top-left corner, x to the right and y down
  // the print, z into it.
  std::vector<Eigen::Vector3d> ChessboardCorners() const;
  int MarkerCount() const { return (squares_x * squares_y) / 2; }

  // board.json; throws Error naming the file and the field.
  static CharucoBoardSpec Load(const std::string& path);
  nlohmann::json ToJson() const;
};

// The board drawn by OpenCV (cv::aruco::CharucoBoard::draw), `texels_per_square` texels a square side,
// no margin: texel (col, row) covers board x in [col, col + 1) and y in [row, row + 1) times
// square_size / texels_per_square. Values 0 (black) or 255 (white).
std::vector<uint8_t> DrawCharucoBoard(const CharucoBoardSpec& board, int texels_per_square, int* width, int* height);

struct IntrinsicCalibrationOptions {
  int min_corners_per_view = 12;  // photos with fewer chessboard corners found are left out
  int min_views = 5;              // fewer usable photos: refused
  double max_view_rms_px = 1.0;   // photos whose reprojection RMS exceeds this are left out, then recalibrated
  int corner_window_px =
      5;  // largest half-size of the saddle-point refinement window, pixels (smaller where the markers come closer)
  bool Check(std::string* why) const;
};

struct CalibrationView {
  std::string file;  // the photo's path
  int markers = 0;   // ArUco markers detected
  int corners = 0;   // chessboard corners interpolated and refined
  bool used = false;
  std::string dropped_reason;  // empty when used
  double rms_px = 0.0;         // reprojection RMS of its corners in the final calibration
};

// What CalibrateIntrinsics found. Bad photos, too few views or a calibration that does not converge
// throw Error; a returned result holds a calibrated camera.
struct IntrinsicCalibrationResult {
  Camera camera;                // OPENCV model, COLMAP's pixel convention
  std::vector<double> std_dev;  // one-sigma uncertainty of fx, fy, cx, cy, k1, k2, p1, p2
  double rms_px = 0.0;          // reprojection RMS over every corner used
  int views_used = 0;
  int corners_used = 0;
  std::vector<CalibrationView> views;
  double total_s = 0.0;
  std::string BriefReport() const;
};

// Calibrates from every image in `directory` (sorted by name; board.json describes the board). The
// image size is every photo's; photos of another size are an Error naming the photo. Too few usable
// photos or corners is an Error saying how many were found and why the others were left out.
IntrinsicCalibrationResult CalibrateIntrinsics(const std::string& directory,
                                               const IntrinsicCalibrationOptions& options);

nlohmann::json ToJson(const IntrinsicCalibrationResult& result);

}  // namespace ibrdf
