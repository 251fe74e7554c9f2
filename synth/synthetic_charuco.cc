#include "synth/synthetic_charuco.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/rigid3.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The printed sheet: the board's texture with a white margin of half a square, on a darker table.
class BoardTexture {
 public:
  BoardTexture(const CharucoPhotoOptions& options) : options_(options) {
    texels_ = DrawCharucoBoard(options.board, options.texels_per_square, &width_, &height_);
    width_m_ = options.board.squares_x * options.board.square_size;
    height_m_ = options.board.squares_y * options.board.square_size;
  }
  // The linear signal at board coordinates (OpenCV's board frame: x right and y down the print from its
  // top-left corner, metres).
  double At(double x, double y) const {
    const double margin = 0.5 * options_.board.square_size;
    if (x < -margin || y < -margin || x >= width_m_ + margin || y >= height_m_ + margin) return options_.background;
    if (x < 0.0 || y < 0.0 || x >= width_m_ || y >= height_m_) return options_.white;
    const int col = std::min(width_ - 1, static_cast<int>(x / width_m_ * width_));
    const int row = std::min(height_ - 1, static_cast<int>(y / height_m_ * height_));
    return texels_[size_t(row) * width_ + col] ? options_.white : options_.black;
  }
  double width_m() const { return width_m_; }
  double height_m() const { return height_m_; }

 private:
  const CharucoPhotoOptions& options_;
  std::vector<uint8_t> texels_;
  int width_ = 0, height_ = 0;
  double width_m_ = 0.0, height_m_ = 0.0;
};

// A seeded view of the board: the camera at a random tilt and azimuth about the board's normal, aimed
// near its centre, rolled, at a distance where the board spans a random fraction of the frame. The
// board frame's z points into the print, so the camera sits on the -z side, the print's top (-y) up.
Rigid3d RandomView(const Camera& camera, const CharucoPhotoOptions& options, const BoardTexture& texture,
                   std::mt19937_64* rng) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double fill = options.min_fill + (options.max_fill - options.min_fill) * uniform(*rng);
  const double distance = camera.FocalX() * texture.width_m() / (fill * camera.width);
  const double tilt = (10.0 + (options.max_tilt_deg - 10.0) * uniform(*rng)) * kDegree;
  const double azimuth = 2.0 * M_PI * uniform(*rng);
  const Eigen::Vector3d board_center(0.5 * texture.width_m(), 0.5 * texture.height_m(), 0.0);
  const Eigen::Vector3d aim =
      board_center + Eigen::Vector3d((2.0 * uniform(*rng) - 1.0) * options.max_offset * texture.width_m(),
                                     (2.0 * uniform(*rng) - 1.0) * options.max_offset * texture.height_m(), 0.0);
  const Eigen::Vector3d center = aim + distance * Eigen::Vector3d(std::sin(tilt) * std::cos(azimuth),
                                                                  std::sin(tilt) * std::sin(azimuth), -std::cos(tilt));
  const double roll = (2.0 * uniform(*rng) - 1.0) * 30.0 * kDegree;
  const Eigen::Vector3d up(std::sin(roll), -std::cos(roll), 0.0);
  return LookAtCameraFromWorld(center, aim, up);
}

// Renders one photo's linear signal: the board plane z = 0 along each ray, distortion included.
Image RenderBoard(const Camera& camera, const Rigid3d& camera_from_board, const BoardTexture& texture,
                  int supersample) {
  const Rigid3d board_from_camera = camera_from_board.Inverse();
  const Eigen::Matrix3d rotation = board_from_camera.rotation.toRotationMatrix();
  const Eigen::Vector3d origin = board_from_camera.translation;
  const double background = texture.At(-1e9, -1e9);
  auto value_at = [&](double px, double py) {
    const Eigen::Vector2d xy = camera.CamPlaneFromImage(Eigen::Vector2d(px, py));
    const Eigen::Vector3d direction = rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    if (!(direction.z() * origin.z() < 0.0)) return background;  // the ray misses the board's plane
    const double t = -origin.z() / direction.z();
    return texture.At(origin.x() + t * direction.x(), origin.y() + t * direction.y());
  };
  const int w = camera.width, h = camera.height;
  std::vector<double> corners(size_t(w + 1) * (h + 1));
  tbb::parallel_for(0, h + 1, [&](int y) {
    for (int x = 0; x <= w; ++x) corners[size_t(y) * (w + 1) + x] = value_at(x, y);
  });
  Image image(w, h, 1);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const double c00 = corners[size_t(y) * (w + 1) + x], c10 = corners[size_t(y) * (w + 1) + x + 1];
      const double c01 = corners[size_t(y + 1) * (w + 1) + x], c11 = corners[size_t(y + 1) * (w + 1) + x + 1];
      double value = c00;
      if (c00 != c10 || c00 != c01 || c00 != c11) {
        double sum = 0.0;
        for (int sy = 0; sy < supersample; ++sy) {
          for (int sx = 0; sx < supersample; ++sx)
            sum += value_at(x + (sx + 0.5) / supersample, y + (sy + 0.5) / supersample);
        }
        value = sum / (supersample * supersample);
      }
      image.at(x, y, 0) = static_cast<float>(value);
    }
  });
  return image;
}

}  // namespace

bool CharucoPhotoOptions::Check(std::string* why) const {
  if (!board.Check(why)) return false;
  if (num_photos < 1 || texels_per_square < 8 || supersample < 1 || supersample > 16) {
    *why = "num_photos >= 1, texels_per_square >= 8, supersample 1 to 16";
    return false;
  }
  if (!(min_fill > 0.0 && min_fill <= max_fill && max_fill <= 2.0) || !(max_tilt_deg >= 10.0 && max_tilt_deg < 80.0) ||
      !(max_offset >= 0.0 && max_offset <= 1.0)) {
    *why = "0 < min_fill <= max_fill <= 2, max_tilt_deg in [10, 80), max_offset in [0, 1]";
    return false;
  }
  if (!(0.0 <= black && black < white && white <= 1.0) || !(background >= 0.0 && background <= 1.0) ||
      !(full_well_e >= 0.0) || !(read_noise_e >= 0.0)) {
    *why = "0 <= black < white <= 1, background in [0, 1], non-negative noise";
    return false;
  }
  return true;
}

std::string CharucoPhotosSummary::BriefReport() const {
  char buffer[120];
  std::snprintf(buffer, sizeof(buffer), "charuco: %d board photos in %.2f s", photos, total_s);
  return buffer;
}

CharucoPhotosSummary WriteCharucoPhotos(const Camera& camera, const CharucoPhotoOptions& options,
                                        const std::string& out_dir, bool overwrite) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("charuco photo options", why);
  if (!camera.Check(&why)) ThrowError("charuco photo camera", why);
  const BoardTexture texture(options);
  AtomicDirectory directory(out_dir, overwrite);
  std::mt19937_64 rng(options.seed);
  nlohmann::json photos = nlohmann::json::array();
  ProgressBar progress("charuco photos", options.num_photos);
  for (int i = 0; i < options.num_photos; ++i) {
    const Rigid3d camera_from_board = RandomView(camera, options, texture, &rng);
    Image image = RenderBoard(camera, camera_from_board, texture, options.supersample);
    // Noise: one random stream per row, seeded from the seed, the photo and the row.
    tbb::parallel_for(0, image.height, [&](int y) {
      std::mt19937_64 row_rng(options.seed * 0x9E3779B97F4A7C15ull + (uint64_t(i) << 32) + uint64_t(y) + 1);
      std::normal_distribution<double> normal(0.0, 1.0);
      for (int x = 0; x < image.width; ++x) {
        double v = image.at(x, y, 0);
        if (options.full_well_e > 0.0) {
          const double electrons = v * options.full_well_e;
          v = (electrons + std::sqrt(electrons) * normal(row_rng) + options.read_noise_e * normal(row_rng)) /
              options.full_well_e;
        }
        image.at(x, y, 0) = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
    });
    char name[32];
    std::snprintf(name, sizeof(name), "charuco-%03d.png", i);
    WriteImage((fs::path(directory.temporary_path()) / name).string(), image, PixelFormat::kUint8);
    const Eigen::Quaterniond& q = camera_from_board.rotation;
    photos.push_back(
        {{"file", name},
         {"camera_from_board",
          {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", ToJson(camera_from_board.translation)}}}});
    progress.Add(1);
  }
  progress.Finish();
  WriteJsonFile((fs::path(directory.temporary_path()) / "board.json").string(), options.board.ToJson());
  const nlohmann::json truth = {{"format", "ibrdf-charuco-truth"},
                                {"version", 1},
                                {"camera",
                                 {{"model", CameraModelName(camera.model)},
                                  {"width", camera.width},
                                  {"height", camera.height},
                                  {"params", camera.params}}},
                                {"seed", options.seed},
                                {"photos", photos}};
  WriteJsonFile((fs::path(directory.temporary_path()) / "truth.json").string(), truth);
  directory.Commit();
  CharucoPhotosSummary summary;
  summary.photos = options.num_photos;
  summary.total_s = timer.ElapsedSeconds();
  summary.success = true;
  return summary;
}

}  // namespace ibrdf
