#include "radiometry/linear_image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <string>

#include "core/error.h"
#include "core/file_util.h"
#include "core/logging.h"

namespace fs = std::filesystem;

namespace ibrdf {

std::shared_ptr<const FlatField> LoadFlatField(const Session& session) {
  if (session.radiometry.flat_field.empty()) return nullptr;
  const std::string path = ResolvePath(session.directory, session.radiometry.flat_field);
  const std::string where = session.manifest_path + ": /radiometry/flat_field";
  RequireFile(path, "flat-field image (" + where + ")");
  std::string key = fs::absolute(path).lexically_normal().string() + "|" + std::to_string(fs::file_size(path)) + "|" +
                    std::to_string(fs::last_write_time(path).time_since_epoch().count()) + "|" +
                    std::to_string(session.camera.width) + "x" + std::to_string(session.camera.height);
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const FlatField>> cache;
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto it = cache.find(key);
    if (it != cache.end()) return it->second;
  }
  const Image image = ReadImage(path);
  if (image.width != session.camera.width || image.height != session.camera.height) {
    ThrowError(path, "flat-field image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                         ", the camera is " + std::to_string(session.camera.width) + "x" +
                         std::to_string(session.camera.height) + " (" + where + ")");
  }
  if (image.channels != 1 && image.channels < 3) {
    ThrowError(path, "flat-field image: expected 1 (grey) or 3+ (RGB) channels, got " + std::to_string(image.channels));
  }
  auto flat = std::make_shared<FlatField>();
  const size_t n = size_t(image.width) * image.height;
  flat->inverse.resize(3 * n);
  double centre_sum = 0.0;
  size_t centre_count = 0;
  for (size_t p = 0; p < n; ++p) {
    for (int c = 0; c < 3; ++c) {
      const float v = image.pixels[p * image.channels + (image.channels == 1 ? 0 : c)];
      if (!(std::isfinite(v) && v > 0.0f)) {
        ThrowError(path, "flat-field image: pixel (" + std::to_string(p % image.width) + ", " +
                             std::to_string(p / image.width) + ") channel " + std::to_string(c) + " is " +
                             std::to_string(v) + "; a relative sensitivity must be positive and finite");
      }
      flat->inverse[3 * p + c] = 1.0f / v;
      const int x = int(p % image.width), y = int(p / image.width);
      if (std::abs(x + 0.5 - 0.5 * image.width) < 0.05 * image.width &&
          std::abs(y + 0.5 - 0.5 * image.height) < 0.05 * image.height) {
        centre_sum += v;
        ++centre_count;
      }
    }
  }
  const double centre = centre_count ? centre_sum / centre_count : 1.0;
  if (std::abs(centre - 1.0) > 0.1) {
    Log(1, "warning: flat-field image " + path + " averages " + std::to_string(centre) +
               " at the image centre (expected about 1: radiance is divided by it as it is)");
  }
  std::lock_guard<std::mutex> lock(mutex);
  cache[key] = flat;
  return flat;
}

void LinearizeImage(const Session& session, size_t photo, Image* image, bool divide_by_exposure) {
  IBRDF_CHECK(photo < session.photos.size());
  const RadiometrySpec& radiometry = session.radiometry;
  const std::shared_ptr<const FlatField> flat = LoadFlatField(session);
  if (flat && (image->width != session.camera.width || image->height != session.camera.height)) {
    ThrowError(session.PhotoPath(photo), "photo is " + std::to_string(image->width) + "x" +
                                             std::to_string(image->height) + ", the camera (and flat field) " +
                                             std::to_string(session.camera.width) + "x" +
                                             std::to_string(session.camera.height));
  }
  const PhotoSpec& spec = session.photos[photo];
  const double scale = divide_by_exposure ? 1.0 / (spec.exposure_s * spec.gain) : 1.0;
  const int channels = image->channels;
  const size_t n = size_t(image->width) * image->height;
  for (size_t p = 0; p < n; ++p) {
    for (int c = 0; c < std::min(channels, 3); ++c) {
      float& v = image->pixels[p * channels + c];
      double linear = std::max(0.0, radiometry.response.ToLinear(v) - radiometry.black_level) * scale;
      if (flat) {
        const float* inverse = &flat->inverse[3 * p];
        linear *= channels == 1 ? (inverse[0] + inverse[1] + inverse[2]) / 3.0 : inverse[c];
      }
      v = static_cast<float>(linear);
    }
  }
}

double SaturationLevel(const RadiometrySpec& radiometry, const Image& image) {
  if (radiometry.saturation_stated) return radiometry.saturation_level;
  return image.floating_point ? std::numeric_limits<double>::infinity() : 1.0;
}

std::vector<uint8_t> SaturatedPixels(const RadiometrySpec& radiometry, const Image& image) {
  const double level = SaturationLevel(radiometry, image);
  const size_t n = size_t(image.width) * image.height;
  std::vector<uint8_t> saturated(n, 0);
  for (size_t p = 0; p < n; ++p) {
    const float* values = &image.pixels[p * image.channels];
    for (int c = 0; c < 3; ++c) {
      if (values[image.channels == 1 ? 0 : c] >= level) saturated[p] = 1;
    }
  }
  return saturated;
}

}  // namespace ibrdf
