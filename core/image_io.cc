#include "core/image_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
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
  // OpenImageIO 2.4 converts integers only through get_int_attribute (get_float_attribute and
  // ParamValue::get_float miss an EXR header's int).
  const double value = p->type().is_floating_point()
                           ? double(spec.get_float_attribute(name, std::numeric_limits<float>::quiet_NaN()))
                           : double(spec.get_int_attribute(name, -1));
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

// The best rational approximation of `value` > 0 with numerator and denominator below 2^31
// (continued fractions): 1/125 stays 1/125, as a camera writes it.
std::pair<uint32_t, uint32_t> Rational(double value) {
  const double limit = 2147483647.0;
  double h0 = 0, h1 = 1, k0 = 1, k1 = 0, x = value;
  for (int i = 0; i < 40; ++i) {
    const double a = std::floor(x);
    const double h2 = a * h1 + h0, k2 = a * k1 + k0;
    if (h2 > limit || k2 > limit) break;
    h0 = h1;
    h1 = h2;
    k0 = k1;
    k1 = k2;
    if (std::abs(h1 / k1 - value) <= 1e-15 * value || x - a < 1e-12) break;
    x = 1.0 / (x - a);
  }
  if (k1 == 0) return {static_cast<uint32_t>(limit), 1};
  return {static_cast<uint32_t>(h1), static_cast<uint32_t>(k1)};
}

// A little-endian TIFF structure holding the EXIF fields of `metadata` (IFD0: Make, Model, DateTime and
// the Exif IFD pointer; the Exif IFD: exposure, f-number, ISO, original time, focal length and the focal
// plane resolution). OpenImageIO 2.4's own encoder turns some exposure times into infinity (0.5 s) and
// others into approximations (0.01 s as 0.009999), so ibrdf writes the rationals itself.
std::string EncodeExif(const PhotoMetadata& m) {
  struct Entry {
    uint16_t tag, type;
    uint32_t count;
    std::string data;  // the value's bytes, little-endian
  };
  auto u16 = [](uint32_t v) { return std::string{char(v & 0xff), char((v >> 8) & 0xff)}; };
  auto u32 = [](uint32_t v) {
    return std::string{char(v & 0xff), char((v >> 8) & 0xff), char((v >> 16) & 0xff), char((v >> 24) & 0xff)};
  };
  auto ascii = [](uint16_t tag, const std::string& text) {
    return Entry{tag, 2, uint32_t(text.size() + 1), text + '\0'};
  };
  auto rational = [&](uint16_t tag, double value) {
    const auto [num, den] = Rational(value);
    return Entry{tag, 5, 1, u32(num) + u32(den)};
  };
  auto short_value = [&](uint16_t tag, double value) {
    return Entry{tag, 3, 1, u16(static_cast<uint32_t>(std::clamp(std::lround(value), 0L, 65535L)))};
  };
  std::vector<Entry> ifd0, exif;
  if (!m.make.empty()) ifd0.push_back(ascii(0x010F, m.make));
  if (!m.model.empty()) ifd0.push_back(ascii(0x0110, m.model));
  if (!m.date_time.empty()) ifd0.push_back(ascii(0x0132, m.date_time));
  if (m.exposure_s) exif.push_back(rational(0x829A, *m.exposure_s));
  if (m.f_number) exif.push_back(rational(0x829D, *m.f_number));
  if (m.iso) exif.push_back(short_value(0x8827, *m.iso));
  exif.push_back(Entry{0x9000, 7, 4, "0230"});  // ExifVersion
  if (!m.date_time.empty()) exif.push_back(ascii(0x9003, m.date_time));
  if (m.focal_length_mm) exif.push_back(rational(0x920A, *m.focal_length_mm));
  if (m.pixels_per_mm) {
    exif.push_back(rational(0xA20E, 10.0 * *m.pixels_per_mm));  // per centimetre (unit 3)
    exif.push_back(rational(0xA20F, 10.0 * *m.pixels_per_mm));
    exif.push_back(short_value(0xA210, 3));
  }
  if (m.focal_length_35mm) exif.push_back(short_value(0xA405, *m.focal_length_35mm));
  // Layout: header (8), IFD0, its values, the Exif IFD, its values. The pointer's value is known once
  // IFD0's size is.
  auto ifd_size = [](const std::vector<Entry>& entries) {
    size_t size = 2 + 12 * entries.size() + 4;
    for (const Entry& e : entries) size += e.data.size() > 4 ? e.data.size() + (e.data.size() & 1) : 0;
    return size;
  };
  ifd0.push_back(Entry{0x8769, 4, 1, u32(0)});
  const uint32_t exif_offset = static_cast<uint32_t>(8 + ifd_size(ifd0));
  ifd0.back().data = u32(exif_offset);
  auto write_ifd = [&](const std::vector<Entry>& entries, uint32_t offset, std::string* out) {
    uint32_t values = offset + 2 + 12 * static_cast<uint32_t>(entries.size()) + 4;
    std::string table = u16(static_cast<uint32_t>(entries.size())), blobs;
    for (const Entry& e : entries) {
      table += u16(e.tag) + u16(e.type) + u32(e.count);
      if (e.data.size() <= 4) {
        table += e.data + std::string(4 - e.data.size(), '\0');
      } else {
        table += u32(values);
        std::string data = e.data;
        if (data.size() & 1) data.push_back('\0');
        blobs += data;
        values += static_cast<uint32_t>(data.size());
      }
    }
    *out += table + u32(0) + blobs;
  };
  std::string tiff = std::string("II*\0", 4) + u32(8);
  write_ifd(ifd0, 8, &tiff);
  write_ifd(exif, exif_offset, &tiff);
  return tiff;
}

// OpenImageIO 2.4 writes no EXIF into PNG files but reads the eXIf chunk (PNG 1.5): insert one, with
// EncodeExif's block, after the IHDR chunk of the PNG file `path`.
void InsertPngExif(const std::string& path, const PhotoMetadata& metadata) {
  const std::string exif = EncodeExif(metadata);
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
  metadata.bits =
      metadata.floating_point ? 0 : spec.get_int_attribute("oiio:BitsPerSample", int(spec.format.size() * 8));
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
