#include "core/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imageio.h>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::unique_ptr<OIIO::ImageInput> Open(const std::string& path) {
  RequireFile(path, "image");
  OIIO::ImageSpec config;
  if (IsRawExtension(path)) {
    // Linear output: without this the RAW reader applies an sRGB curve.
    config.attribute("raw:ColorSpace", "sRGB-linear");
    config.attribute("raw:auto_bright", 0);
    config.attribute("raw:use_camera_wb", 1);
  }
  auto input = OIIO::ImageInput::open(path, &config);
  if (!input) ThrowError(path, "cannot read image: " + OIIO::geterror());
  return input;
}

}  // namespace

bool IsRawExtension(const std::string& path) {
  static const char* const kRaw[] = {".cr2", ".cr3", ".nef", ".arw", ".dng", ".orf", ".rw2",
                                     ".raf", ".pef", ".srw", ".crw", ".erf", ".3fr", ".iiq"};
  const std::string ext = LowerExtension(path);
  return std::any_of(std::begin(kRaw), std::end(kRaw), [&](const char* e) { return ext == e; });
}

double BilinearLuminance(const Image& image, double px, double py) {
  const double x = px - 0.5, y = py - 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (!(x0 >= 0 && y0 >= 0 && x0 + 1 < image.width && y0 + 1 < image.height)) return NAN;
  const double fx = x - x0, fy = y - y0;
  auto luminance = [&](int xi, int yi) {
    if (image.channels < 3) return double(image.at(xi, yi, 0));
    return 0.2126 * image.at(xi, yi, 0) + 0.7152 * image.at(xi, yi, 1) + 0.0722 * image.at(xi, yi, 2);
  };
  return (1 - fx) * (1 - fy) * luminance(x0, y0) + fx * (1 - fy) * luminance(x0 + 1, y0) +
         (1 - fx) * fy * luminance(x0, y0 + 1) + fx * fy * luminance(x0 + 1, y0 + 1);
}

ImageSpec ReadImageSpec(const std::string& path) {
  auto input = Open(path);
  const OIIO::ImageSpec& spec = input->spec();
  return {spec.width, spec.height, spec.nchannels};
}

Image ReadImage(const std::string& path) {
  Image image;
  ReadImage(path, &image);
  return image;
}

void ReadImage(const std::string& path, Image* image) {
  auto input = Open(path);
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) ThrowError(path, "image is empty");
  image->width = spec.width;
  image->height = spec.height;
  image->channels = spec.nchannels;
  image->pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);  // every value is overwritten
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image->pixels.data())) {
    ThrowError(path, "cannot decode image: " + input->geterror());
  }
  input->close();
}

void WriteImage(const std::string& path, const Image& image, PixelFormat format) {
  IBRDF_CHECK(image.pixels.size() == size_t(image.width) * image.height * image.channels);
  AtomicFile file(path);
  auto output = OIIO::ImageOutput::create(file.temporary_path());
  if (!output) ThrowError(path, "no image writer for this extension: " + OIIO::geterror());
  OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;
  switch (format) {
    case PixelFormat::kUint8:
      type = OIIO::TypeDesc::UINT8;
      break;
    case PixelFormat::kUint16:
      type = OIIO::TypeDesc::UINT16;
      break;
    case PixelFormat::kHalf:
      type = OIIO::TypeDesc::HALF;
      break;
    case PixelFormat::kFloat:
      type = OIIO::TypeDesc::FLOAT;
      break;
  }
  OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
  if (LowerExtension(path) == ".exr") spec.attribute("compression", "zip");
  // Fast deflate: noisy 16-bit photos barely compress, and level 6 costs 5x the time.
  if (LowerExtension(path) == ".png") spec.attribute("png:compressionLevel", 1);
  if (!output->open(file.temporary_path(), spec) || !output->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) ||
      !output->close()) {
    ThrowError(path, "cannot write image: " + output->geterror());
  }
  file.Commit();
}

}  // namespace ibrdf
