// The OpenImageIO half of core/image_io.h, built as a module (libibrdf_oiio.so) that image_io.cc loads
// with dlopen the first time a file needs it (EXR, TIFF, camera RAW, PNG with alpha or a palette, and
// every write). OpenImageIO links about 260 shared libraries (OpenCV, FFmpeg, OpenVDB ...), whose
// loading cost a light subcommand half a second at start-up. The functions have C names so that
// dlsym finds them; they report failure in `error` instead of throwing across the module boundary.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
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
    // Linear camera RGB (docs/radiometry.md): LibRaw subtracts the file's black level and scales its
    // white (saturation) level to full scale, then demosaics (AHD); no colour matrix ("raw"), no white
    // balance (unit multipliers, neither the camera's nor the daylight pre-multipliers), no automatic
    // brightening and no lowering of the white level to the brightest pixel (adjust_maximum_thr 0).
    config.attribute("raw:ColorSpace", "raw");
    config.attribute("raw:use_camera_wb", 0);
    const float unit_multipliers[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    config.attribute("raw:user_mul", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 4), unit_multipliers);
    config.attribute("raw:auto_bright", 0);
    config.attribute("raw:adjust_maximum_thr", 0.0f);
    config.attribute("raw:Demosaic", "AHD");
  }
  auto input = OIIO::ImageInput::open(path, &config);
  if (!input) *error = "cannot read image: " + OIIO::geterror();
  return input;
}

// A numeric attribute of `spec` (any numeric type, the first element of an array), if present.
std::optional<double> Number(const OIIO::ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name);
  if (!p || p->type().basetype == OIIO::TypeDesc::STRING) return std::nullopt;
  // OpenImageIO 2.4 converts integers only through get_int_attribute (get_float_attribute and
  // ParamValue::get_float miss an EXR header's int).
  const double value = p->type().is_floating_point()
                           ? double(spec.get_float_attribute(name, std::numeric_limits<float>::quiet_NaN()))
                           : double(spec.get_int_attribute(name, -1));
  if (!std::isfinite(value) || value <= 0.0) return std::nullopt;
  return value;
}

// The EXIF fields of `metadata` as OpenImageIO attributes.
void SetMetadata(const ibrdf::PhotoMetadata& metadata, OIIO::ImageSpec* spec) {
  if (metadata.exposure_s) spec->attribute("ExposureTime", static_cast<float>(*metadata.exposure_s));
  if (metadata.f_number) spec->attribute("FNumber", static_cast<float>(*metadata.f_number));
  if (metadata.iso) spec->attribute("Exif:PhotographicSensitivity", static_cast<int>(std::lround(*metadata.iso)));
  if (metadata.focal_length_mm) spec->attribute("Exif:FocalLength", static_cast<float>(*metadata.focal_length_mm));
  if (metadata.focal_length_35mm) {
    spec->attribute("Exif:FocalLengthIn35mmFilm", static_cast<int>(std::lround(*metadata.focal_length_35mm)));
  }
  if (metadata.pixels_per_mm) {
    // Unit 3: centimetres.
    spec->attribute("Exif:FocalPlaneXResolution", static_cast<float>(10.0 * *metadata.pixels_per_mm));
    spec->attribute("Exif:FocalPlaneYResolution", static_cast<float>(10.0 * *metadata.pixels_per_mm));
    spec->attribute("Exif:FocalPlaneResolutionUnit", 3);
  }
  if (!metadata.make.empty()) spec->attribute("Make", metadata.make);
  if (!metadata.model.empty()) spec->attribute("Model", metadata.model);
  if (!metadata.date_time.empty()) {
    spec->attribute("DateTime", metadata.date_time);
    spec->attribute("Exif:DateTimeOriginal", metadata.date_time);
  }
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

// The header and EXIF fields of `path` (a camera RAW file when `raw`); false with `error` set on failure.
__attribute__((visibility("default"))) bool IbrdfOiioReadMetadata(const std::string& path, bool raw,
                                                                  ibrdf::PhotoMetadata* metadata, std::string* error) {
  auto input = Open(path, raw, error);
  if (!input) return false;
  const OIIO::ImageSpec& spec = input->spec();
  metadata->width = spec.width;
  metadata->height = spec.height;
  metadata->channels = spec.nchannels;
  metadata->raw = raw;
  metadata->floating_point = spec.format.is_floating_point() && !metadata->raw;
  metadata->bits =
      metadata->floating_point ? 0 : spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
  metadata->exposure_s = Number(spec, "ExposureTime");
  metadata->f_number = Number(spec, "FNumber");
  metadata->iso = Number(spec, "Exif:PhotographicSensitivity");
  if (!metadata->iso) metadata->iso = Number(spec, "Exif:ISOSpeedRatings");
  metadata->focal_length_mm = Number(spec, "Exif:FocalLength");
  metadata->focal_length_35mm = Number(spec, "Exif:FocalLengthIn35mmFilm");
  if (const std::optional<double> resolution = Number(spec, "Exif:FocalPlaneXResolution")) {
    // FocalPlaneResolutionUnit: 2 inch (the default), 3 centimetre, 4 millimetre.
    const int unit = spec.get_int_attribute("Exif:FocalPlaneResolutionUnit", 2);
    const double mm_per_unit = unit == 3 ? 10.0 : unit == 4 ? 1.0 : 25.4;
    metadata->pixels_per_mm = *resolution / mm_per_unit;
  }
  metadata->make = spec.get_string_attribute("Make");
  metadata->model = spec.get_string_attribute("Model");
  metadata->date_time = spec.get_string_attribute("Exif:DateTimeOriginal", spec.get_string_attribute("DateTime"));
  input->close();
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
  image->floating_point = spec.format.is_floating_point() && !raw;
  image->pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);  // every value is overwritten
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image->pixels.data())) {
    *error = "cannot decode image: " + input->geterror();
    return false;
  }
  input->close();
  return true;
}

// Writes `image` to `path` (the writer chosen by the extension) with `format` as the stored pixel type
// (an ibrdf::PixelFormat) and, for formats whose EXIF OpenImageIO writes (not PNG), `metadata` when not
// null. False with `error` set on failure.
__attribute__((visibility("default"))) bool IbrdfOiioWrite(const std::string& path, const ibrdf::Image& image,
                                                           int format, const ibrdf::PhotoMetadata* metadata,
                                                           std::string* error) {
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
  if (metadata && LowerExtension(path) != ".png") SetMetadata(*metadata, &spec);
  if (!output->open(path, spec) || !output->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) ||
      !output->close()) {
    *error = "cannot write image: " + output->geterror();
    return false;
  }
  return true;
}

}  // extern "C"
