#include "core/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/tiffutils.h>

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
  if (!input) ThrowError(path, "cannot read image: " + OIIO::geterror());
  return input;
}

// A numeric attribute of `spec` (any numeric type, the first element of an array), if present.
std::optional<double> Number(const OIIO::ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name);
  if (!p || p->type().basetype == OIIO::TypeDesc::STRING) return std::nullopt;
  const double value = p->get_float();
  if (!std::isfinite(value) || value <= 0.0) return std::nullopt;
  return value;
}

// The EXIF fields of `metadata` as OpenImageIO attributes.
void SetMetadata(const PhotoMetadata& metadata, OIIO::ImageSpec* spec) {
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

uint32_t Crc32(const char* data, size_t size, uint32_t crc) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ static_cast<uint8_t>(data[i])) & 0xff] ^ (crc >> 8);
  return ~crc;
}

void AppendBigEndian(uint32_t value, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>((value >> shift) & 0xff));
}

// OpenImageIO 2.4 writes no EXIF into PNG files but reads the eXIf chunk (PNG 1.5): insert one, with
// the EXIF block OpenImageIO encodes, after the IHDR chunk of the PNG file `path`.
void InsertPngExif(const std::string& path, const PhotoMetadata& metadata) {
  OIIO::ImageSpec spec;
  SetMetadata(metadata, &spec);
  std::vector<char> exif;
  OIIO::encode_exif(spec, exif);
  // encode_exif may prefix JPEG's "Exif\0\0"; the PNG chunk holds the TIFF structure only.
  if (exif.size() >= 6 && std::string(exif.data(), 4) == "Exif") exif.erase(exif.begin(), exif.begin() + 6);
  std::string png;
  {
    std::ifstream in(path, std::ios::binary);
    png.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  IBRDF_CHECK(png.size() > 33 && png.compare(1, 3, "PNG") == 0 && png.compare(12, 4, "IHDR") == 0) << path;
  std::string chunk;
  AppendBigEndian(static_cast<uint32_t>(exif.size()), &chunk);
  chunk += "eXIf";
  chunk.append(exif.data(), exif.size());
  AppendBigEndian(Crc32(chunk.data() + 4, chunk.size() - 4, 0), &chunk);
  png.insert(33, chunk);  // signature (8) + IHDR (4 + 4 + 13 + 4)
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(png.data(), static_cast<std::streamsize>(png.size()));
  if (!out) ThrowError(path, "cannot write the EXIF chunk");
}

}  // namespace

PhotoMetadata ReadPhotoMetadata(const std::string& path) {
  auto input = Open(path);
  const OIIO::ImageSpec& spec = input->spec();
  PhotoMetadata metadata;
  metadata.width = spec.width;
  metadata.height = spec.height;
  metadata.channels = spec.nchannels;
  metadata.raw = IsRawExtension(path);
  metadata.floating_point = spec.format.is_floating_point() && !metadata.raw;
  metadata.bits = metadata.floating_point ? 0 : spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
  metadata.exposure_s = Number(spec, "ExposureTime");
  metadata.f_number = Number(spec, "FNumber");
  metadata.iso = Number(spec, "Exif:PhotographicSensitivity");
  if (!metadata.iso) metadata.iso = Number(spec, "Exif:ISOSpeedRatings");
  metadata.focal_length_mm = Number(spec, "Exif:FocalLength");
  metadata.focal_length_35mm = Number(spec, "Exif:FocalLengthIn35mmFilm");
  if (const std::optional<double> resolution = Number(spec, "Exif:FocalPlaneXResolution")) {
    // FocalPlaneResolutionUnit: 2 inch (the default), 3 centimetre, 4 millimetre.
    const int unit = spec.get_int_attribute("Exif:FocalPlaneResolutionUnit", 2);
    const double mm_per_unit = unit == 3 ? 10.0 : unit == 4 ? 1.0 : 25.4;
    metadata.pixels_per_mm = *resolution / mm_per_unit;
  }
  metadata.make = spec.get_string_attribute("Make");
  metadata.model = spec.get_string_attribute("Model");
  metadata.date_time = spec.get_string_attribute("Exif:DateTimeOriginal", spec.get_string_attribute("DateTime"));
  input->close();
  return metadata;
}

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
  auto input = Open(path);
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) ThrowError(path, "image is empty");
  Image image(spec.width, spec.height, spec.nchannels);
  image.floating_point = spec.format.is_floating_point() && !IsRawExtension(path);
  if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    ThrowError(path, "cannot decode image: " + input->geterror());
  }
  input->close();
  return image;
}

void WriteImage(const std::string& path, const Image& image, PixelFormat format, const PhotoMetadata* metadata) {
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
  const bool png = LowerExtension(path) == ".png";
  if (metadata && !png) SetMetadata(*metadata, &spec);
  if (!output->open(file.temporary_path(), spec) || !output->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) ||
      !output->close()) {
    ThrowError(path, "cannot write image: " + output->geterror());
  }
  output.reset();
  if (metadata && png) InsertPngExif(file.temporary_path(), *metadata);
  file.Commit();
}

}  // namespace ibrdf
