#include "align/intrinsic_calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "align/markers.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

cv::Ptr<cv::aruco::CharucoBoard> MakeBoard(const CharucoBoardSpec& spec, const std::string& where) {
  std::string why;
  if (!spec.Check(&why)) ThrowError(where, why);
  const MarkerDictionary dictionary(spec.dictionary, where + ": dictionary");
  if (spec.MarkerCount() > dictionary.size()) {
    ThrowError(where, "a " + std::to_string(spec.squares_x) + " x " + std::to_string(spec.squares_y) + " board needs " +
                          std::to_string(spec.MarkerCount()) + " markers; " + spec.dictionary + " has " +
                          std::to_string(dictionary.size()));
  }
  return cv::aruco::CharucoBoard::create(
      spec.squares_x, spec.squares_y, static_cast<float>(spec.square_size), static_cast<float>(spec.marker_size),
      cv::aruco::getPredefinedDictionary(cv::aruco::PREDEFINED_DICTIONARY_NAME(dictionary.id_for_opencv())));
}

bool IsImageFile(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* known : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".bmp", ".pgm", ".ppm"}) {
    if (extension == known) return true;
  }
  return IsRawExtension(path.string());
}

// The corners of one photo: OpenCV's pixel convention (centres at integers).
struct ViewCorners {
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
};

ViewCorners FindCorners(const Image& image, const cv::Ptr<cv::aruco::CharucoBoard>& board,
                        const IntrinsicCalibrationOptions& options, CalibrationView* view) {
  // Grey as stored: 8-bit with a display gamma for the marker detector (dark photos still threshold),
  // float for the saddle-point refinement.
  cv::Mat grey(image.height, image.width, CV_32FC1), grey8(image.height, image.width, CV_8UC1);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      double v = image.channels >= 3
                     ? 0.2126 * image.at(x, y, 0) + 0.7152 * image.at(x, y, 1) + 0.0722 * image.at(x, y, 2)
                     : image.at(x, y, 0);
      if (!std::isfinite(v)) v = 0.0;
      v = std::clamp(v, 0.0, 1.0);
      grey.at<float>(y, x) = static_cast<float>(v);
      grey8.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(255.0 * std::pow(v, 1.0 / 2.2)));
    }
  }
  std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
  std::vector<int> marker_ids;
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  cv::aruco::detectMarkers(grey8, board->dictionary, marker_corners, marker_ids, parameters, rejected);
  cv::aruco::refineDetectedMarkers(grey8, board, marker_corners, marker_ids, rejected);
  view->markers = static_cast<int>(marker_ids.size());
  ViewCorners found;
  if (marker_ids.empty()) return found;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey8, board, found.corners, found.ids);
  if (found.corners.empty()) return found;
  // OpenCV's interpolation refines to 0.1 px; the saddle points again, to 1e-4 px, in a window that
  // stays inside the squares around each corner.
  double spacing = 1e30;
  for (size_t a = 0; a < found.corners.size(); ++a) {
    for (size_t b = a + 1; b < found.corners.size(); ++b) {
      spacing = std::min(spacing, double(cv::norm(found.corners[a] - found.corners[b])));
    }
  }
  // The window must stay clear of the markers' borders, (square - marker) / 2 from each corner: wider,
  // their edges pull the saddle point (0.3 px RMS at 5 px against 0.1 px at 3 px, board squares of 28 px).
  const double margin_px = 0.5 * (1.0 - board->getMarkerLength() / board->getSquareLength()) * spacing;
  const int half = std::max(2, std::min(options.corner_window_px, static_cast<int>(0.8 * margin_px)));
  cv::cornerSubPix(grey, found.corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  return found;
}

}  // namespace

bool CharucoBoardSpec::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(squares_x, 3);
  IBRDF_CHECK_OPTION_GE(squares_y, 3);
  if (squares_y % 2 == 0) {
    *why = "squares_y must be odd (got " + std::to_string(squares_y) +
           "): boards with an even number of rows differ between OpenCV versions";
    return false;
  }
  IBRDF_CHECK_OPTION_GT(square_size, 0.0);
  IBRDF_CHECK_OPTION_GT(marker_size, 0.0);
  IBRDF_CHECK_OPTION_LT(marker_size, square_size);
  return true;
}

std::vector<Eigen::Vector3d> CharucoBoardSpec::ChessboardCorners() const {
  const cv::Ptr<cv::aruco::CharucoBoard> board = MakeBoard(*this, "ChArUco board");
  std::vector<Eigen::Vector3d> corners;
  for (const cv::Point3f& p : board->chessboardCorners) corners.emplace_back(p.x, p.y, p.z);
  return corners;
}

CharucoBoardSpec CharucoBoardSpec::Load(const std::string& path) {
  RequireFile(path, "ChArUco board description");
  const nlohmann::json json = ReadJsonFile(path);
  JsonObject root(json, path);
  if (root.String("format") != "ibrdf-charuco-board")
    ThrowError(root.Where("format"), "expected \"ibrdf-charuco-board\"");
  if (root.Integer("version") != 1) ThrowError(root.Where("version"), "expected 1");
  CharucoBoardSpec spec;
  spec.dictionary = root.String("dictionary");
  spec.squares_x = root.Integer("squares_x");
  spec.squares_y = root.Integer("squares_y");
  spec.square_size = root.Number("square_size");
  spec.marker_size = root.Number("marker_size");
  root.Finish();
  MakeBoard(spec, path);  // every check, the dictionary's size included
  return spec;
}

nlohmann::json CharucoBoardSpec::ToJson() const {
  return {{"format", "ibrdf-charuco-board"}, {"version", 1},           {"dictionary", dictionary},
          {"squares_x", squares_x},          {"squares_y", squares_y}, {"square_size", square_size},
          {"marker_size", marker_size}};
}

std::vector<uint8_t> DrawCharucoBoard(const CharucoBoardSpec& board, int texels_per_square, int* width, int* height) {
  IBRDF_CHECK(texels_per_square >= 1);
  const cv::Ptr<cv::aruco::CharucoBoard> charuco = MakeBoard(board, "ChArUco board");
  *width = board.squares_x * texels_per_square;
  *height = board.squares_y * texels_per_square;
  cv::Mat image;
  charuco->draw(cv::Size(*width, *height), image, 0, 1);
  IBRDF_CHECK(image.cols == *width && image.rows == *height && image.type() == CV_8UC1);
  std::vector<uint8_t> texels(size_t(*width) * *height);
  for (int y = 0; y < *height; ++y) {
    for (int x = 0; x < *width; ++x) texels[size_t(y) * *width + x] = image.at<uint8_t>(y, x) > 127 ? 255 : 0;
  }
  return texels;
}

bool IntrinsicCalibrationOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(min_corners_per_view, 6);
  IBRDF_CHECK_OPTION_GE(min_views, 3);
  IBRDF_CHECK_OPTION_GT(max_view_rms_px, 0.0);
  IBRDF_CHECK_OPTION_GE(corner_window_px, 2);
  return true;
}

IntrinsicCalibrationResult CalibrateIntrinsics(const std::string& directory,
                                               const IntrinsicCalibrationOptions& options) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("calibration options", why);
  if (!fs::is_directory(directory)) ThrowError(directory, "is not a folder of ChArUco board photos");
  const std::string board_path = (fs::path(directory) / "board.json").string();
  const CharucoBoardSpec spec = CharucoBoardSpec::Load(board_path);
  const cv::Ptr<cv::aruco::CharucoBoard> board = MakeBoard(spec, board_path);

  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) ThrowError(directory, "holds no photos (png, jpg, tif, exr or camera RAW) of the board");
  const ImageSpec size = ReadImageSpec(files.front());
  for (const std::string& file : files) {
    const ImageSpec spec_i = ReadImageSpec(file);
    if (spec_i.width != size.width || spec_i.height != size.height) {
      ThrowError(file, "is " + std::to_string(spec_i.width) + "x" + std::to_string(spec_i.height) +
                           ", the first photo " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                           ": one camera, one size");
    }
  }

  IntrinsicCalibrationResult result;
  result.views.resize(files.size());
  std::vector<ViewCorners> found(files.size());
  ProgressBar progress("board corners", files.size());
  tbb::parallel_for(size_t(0), files.size(), [&](size_t i) {
    CalibrationView& view = result.views[i];
    view.file = files[i];
    found[i] = FindCorners(ReadImage(files[i]), board, options, &view);
    view.corners = static_cast<int>(found[i].ids.size());
    if (view.markers == 0) {
      view.dropped_reason = "no marker of the board found";
    } else if (view.corners < options.min_corners_per_view) {
      view.dropped_reason = "only " + std::to_string(view.corners) + " chessboard corners found (need " +
                            std::to_string(options.min_corners_per_view) + ")";
    } else if (cv::aruco::testCharucoCornersCollinear(board, found[i].ids)) {
      view.dropped_reason = "the corners found lie on one line";
    } else {
      view.used = true;
    }
    progress.Add(1);
  });
  progress.Finish();

  // Calibrates on the used views; returns the RMS and fills per-view RMS.
  cv::Mat camera_matrix, distortion, std_intrinsics;
  auto calibrate = [&]() {
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<std::vector<int>> ids;
    std::vector<size_t> index;
    for (size_t i = 0; i < files.size(); ++i) {
      if (!result.views[i].used) continue;
      corners.push_back(found[i].corners);
      ids.push_back(found[i].ids);
      index.push_back(i);
    }
    if (static_cast<int>(corners.size()) < options.min_views) {
      std::string reasons;
      for (const CalibrationView& view : result.views) {
        if (!view.used) reasons += "\n  " + fs::path(view.file).filename().string() + ": " + view.dropped_reason;
      }
      ThrowError(directory, "only " + std::to_string(corners.size()) + " of " + std::to_string(files.size()) +
                                " photos show enough of the board (need " + std::to_string(options.min_views) + ")" +
                                reasons);
    }
    std::vector<cv::Mat> rvecs, tvecs;
    cv::Mat std_extrinsics, per_view;
    camera_matrix = cv::Mat();
    distortion = cv::Mat();
    const double rms = cv::aruco::calibrateCameraCharuco(
        corners, ids, board, cv::Size(size.width, size.height), camera_matrix, distortion, rvecs, tvecs, std_intrinsics,
        std_extrinsics, per_view, cv::CALIB_FIX_K3,
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, DBL_EPSILON));
    for (size_t k = 0; k < index.size(); ++k) result.views[index[k]].rms_px = per_view.at<double>(static_cast<int>(k));
    return rms;
  };
  double rms = calibrate();
  bool dropped = false;
  for (CalibrationView& view : result.views) {
    if (view.used && view.rms_px > options.max_view_rms_px) {
      view.used = false;
      view.dropped_reason =
          "reprojection RMS " + std::to_string(view.rms_px) + " px above " + std::to_string(options.max_view_rms_px);
      dropped = true;
    }
  }
  if (dropped) rms = calibrate();
  if (!std::isfinite(rms)) ThrowError(directory, "the calibration did not converge");

  const double* k = camera_matrix.ptr<double>();
  const double* d = distortion.ptr<double>();
  // OpenCV's pixel centres are at integers, COLMAP's at +0.5.
  result.camera =
      Camera::Create(CameraModelId::kOpenCV, size.width, size.height,
                     {k[0], k[4], k[2] + 0.5, k[5] + 0.5, d[0], d[1], d[2], d[3]}, directory + ": calibrated camera");
  for (int p = 0; p < 8; ++p) result.std_dev.push_back(std_intrinsics.at<double>(p));
  result.rms_px = rms;
  for (const CalibrationView& view : result.views) {
    if (!view.used) continue;
    ++result.views_used;
    result.corners_used += view.corners;
  }
  result.total_s = timer.ElapsedSeconds();
  return result;
}

std::string IntrinsicCalibrationResult::BriefReport() const {
  const std::vector<double>& p = camera.params;
  char buffer[400];
  std::snprintf(buffer, sizeof(buffer),
                "calibration: %d of %zu board photos, %d corners, RMS %.3f px; fx %.2f fy %.2f cx %.2f cy %.2f "
                "k1 %.5f k2 %.5f p1 %.6f p2 %.6f; %.2f s",
                views_used, views.size(), corners_used, rms_px, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7],
                total_s);
  return buffer;
}

nlohmann::json ToJson(const IntrinsicCalibrationResult& result) {
  nlohmann::json views = nlohmann::json::array();
  for (const CalibrationView& view : result.views) {
    nlohmann::json entry = {
        {"file", view.file}, {"markers", view.markers}, {"corners", view.corners}, {"used", view.used}};
    if (view.used) {
      entry["rms_px"] = view.rms_px;
    } else {
      entry["dropped"] = view.dropped_reason;
    }
    views.push_back(entry);
  }
  return {{"camera",
           {{"model", CameraModelName(result.camera.model)},
            {"width", result.camera.width},
            {"height", result.camera.height},
            {"params", result.camera.params}}},
          {"std_dev", result.std_dev},
          {"rms_px", result.rms_px},
          {"views_used", result.views_used},
          {"corners_used", result.corners_used},
          {"views", views},
          {"total_s", result.total_s}};
}

}  // namespace ibrdf
