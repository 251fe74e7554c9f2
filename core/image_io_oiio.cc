// The OpenImageIO half of core/image_io.h, built as a module (libibrdf_oiio.so) that image_io.cc loads
// with dlopen the first time a file needs it (EXR, TIFF, camera RAW, PNG with alpha or a palette, and
// every write). OpenImageIO links about 260 shared libraries (OpenCV, FFmpeg, OpenVDB ...), whose
// loading cost a light subcommand half a second at start-up. The functions have C names so that
// dlsym finds them; they report failure in `error` instead of throwing across the module boundary.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

#include "core/image_io.h"

namespace {

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::unique_ptr<OIIO::ImageInput> Open(const std::string& path, bool raw, std::string* error) {
  OIIO::ImageSpec config;
  if (raw) {
    // Linear output: without this the RAW reader applies an sRGB curve.
    config.attribute("raw:ColorSpace", "sRGB-linear");
    config.attribute("raw:auto_bright", 0);
    config.attribute("raw:use_camera_wb", 1);
  }
  auto input = OIIO::ImageInput::open(path, &config);
  if (!input) *error = "cannot read image: " + OIIO::geterror();
  return input;
}

}  // namespace

extern "C" {

// The size and channel count of `path` (a camera RAW file when `raw`); false with `error` set on failure.
__attribute__((visibility("default"))) bool IbrdfOiioReadSpec(const std::string& path, bool raw, ibrdf::ImageSpec* spec,
                                                              std::string* error) {
  auto input = Open(path, raw, error);
  if (!input) return false;
  *spec = {input->spec().width, input->spec().height, input->spec().nchannels};
  return true;
}

// Decodes `path` into `image` as float, integer formats normalized to [0, 1]; the pixel buffer is
// reused when large enough. False with `error` set on failure.
__attribute__((visibility("default"))) bool IbrdfOiioRead(const std::string& path, bool raw, ibrdf::Image* image,
                                                          std::string* error) {
  auto input = Open(path, raw, error);
  if (!input) return false;
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    *error = "image is empty";
    return false;
  }
  image->width = spec.width;
  image->height = spec.height;
  image->channels = spec.nchannels;
  image->pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);  // every value is overwritten
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image->pixels.data())) {
    *error = "cannot decode image: " + input->geterror();
    return false;
  }
  input->close();
  return true;
}

// Writes `image` to `path` (the writer chosen by the extension) with `format` as the stored pixel type
// (an ibrdf::PixelFormat). False with `error` set on failure.
__attribute__((visibility("default"))) bool IbrdfOiioWrite(const std::string& path, const ibrdf::Image& image,
                                                           int format, std::string* error) {
  auto output = OIIO::ImageOutput::create(path);
  if (!output) {
    *error = "no image writer for this extension: " + OIIO::geterror();
    return false;
  }
  OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;
  switch (static_cast<ibrdf::PixelFormat>(format)) {
    case ibrdf::PixelFormat::kUint8:
      type = OIIO::TypeDesc::UINT8;
      break;
    case ibrdf::PixelFormat::kUint16:
      type = OIIO::TypeDesc::UINT16;
      break;
    case ibrdf::PixelFormat::kHalf:
      type = OIIO::TypeDesc::HALF;
      break;
    case ibrdf::PixelFormat::kFloat:
      type = OIIO::TypeDesc::FLOAT;
      break;
  }
  OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
  if (LowerExtension(path) == ".exr") spec.attribute("compression", "zip");
  // Fast deflate: noisy 16-bit photos barely compress, and level 6 costs 5x the time.
  if (LowerExtension(path) == ".png") spec.attribute("png:compressionLevel", 1);
  if (!output->open(path, spec) || !output->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) ||
      !output->close()) {
    *error = "cannot write image: " + output->geterror();
    return false;
  }
  return true;
}

}  // extern "C"
