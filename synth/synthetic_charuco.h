// Synthetic photos of a ChArUco board for the intrinsic calibration: OpenCV draws
// the board (cv::aruco::CharucoBoard::draw, through align/intrinsic_calibration.h) into a texture, which
// is rendered as a textured plane through a session's camera, lens distortion included, from varied
// seeded poses: pixels whose corners see different texels are supersampled (n x n rays), then shot
// and read noise and 8-bit quantization are applied. The board's true poses go into truth.json.
#pragma once

#include <cstdint>
#include <string>

#include "align/intrinsic_calibration.h"
#include "core/camera.h"

namespace ibrdf {

struct CharucoPhotoOptions {
  CharucoBoardSpec board;  // the board (OpenCV 4.6 layout)
  int num_photos = 12;
  int texels_per_square = 48;  // texture resolution of the drawn board
  int supersample = 4;         // n x n rays for pixels on an edge (uniform pixels take one)
  double min_fill = 0.55;      // the board's width as a fraction of the image width, drawn in [min_fill, max_fill]
  double max_fill = 0.9;
  double max_tilt_deg = 45.0;  // the viewing direction's angle from the board's normal, drawn in [10, max]
  double max_offset = 0.5;     // the aim point, off the board's centre, as a fraction of its size (boards reaching the
                               // frame's corners pin the distortion down)
  double white = 0.8;          // linear signal of the paper (fraction of full scale)
  double black = 0.05;         // of the printed black
  double background = 0.15;    // of the table around the board (the paper has a half-square white margin)
  double full_well_e = 20000.0;  // shot noise: electrons at full scale; 0 = none
  double read_noise_e = 4.0;     // read noise, electrons
  uint64_t seed = 7;
  bool Check(std::string* why) const;
};

struct CharucoPhotosSummary {
  bool success = false;
  int photos = 0;
  double total_s = 0.0;
  std::string BriefReport() const;
};

// Writes `out_dir`: board.json, truth.json (the camera and each photo's camera_from_board) and
// charuco-NNN.png (8-bit grey, the camera's size). The folder appears only when complete.
CharucoPhotosSummary WriteCharucoPhotos(const Camera& camera, const CharucoPhotoOptions& options,
                                        const std::string& out_dir, bool overwrite);

}  // namespace ibrdf
