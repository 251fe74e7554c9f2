#include "core/image_io.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include <dlfcn.h>
#include <png.h>
#include <unistd.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {
namespace {

// The OpenImageIO module (core/image_io_oiio.cc), loaded on first use.
struct OiioModule {
  bool (*read_spec)(const std::string&, bool, ImageSpec*, std::string*) = nullptr;
  bool (*read)(const std::string&, bool, Image*, std::string*) = nullptr;
  bool (*read_metadata)(const std::string&, bool, PhotoMetadata*, std::string*) = nullptr;
  bool (*write)(const std::string&, const Image&, int, const PhotoMetadata*, std::string*) = nullptr;
};

std::vector<std::string> OiioModuleCandidates() {
  if (const char* env = std::getenv("IBRDF_OIIO_MODULE")) return {env};
  std::vector<std::string> candidates;
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error)
    candidates.push_back((self.parent_path() / ".." / "lib" / "ibrdf" / "libibrdf_oiio.so").lexically_normal());
#ifdef IBRDF_OIIO_MODULE_BUILD_PATH
  candidates.push_back(IBRDF_OIIO_MODULE_BUILD_PATH);
#endif
  return candidates;
}

const OiioModule& Oiio(const std::string& path) {
  static const OiioModule module = [&] {
    std::string tried;
    for (const std::string& candidate : OiioModuleCandidates()) {
      if (void* handle = dlopen(candidate.c_str(), RTLD_NOW | RTLD_LOCAL)) {
        OiioModule m;
        m.read_spec = reinterpret_cast<decltype(m.read_spec)>(dlsym(handle, "IbrdfOiioReadSpec"));
        m.read = reinterpret_cast<decltype(m.read)>(dlsym(handle, "IbrdfOiioRead"));
        m.read_metadata = reinterpret_cast<decltype(m.read_metadata)>(dlsym(handle, "IbrdfOiioReadMetadata"));
        m.write = reinterpret_cast<decltype(m.write)>(dlsym(handle, "IbrdfOiioWrite"));
        IBRDF_CHECK(m.read_spec && m.read && m.read_metadata && m.write) << candidate << " lacks the image functions";
        return m;
      }
      tried += (tried.empty() ? "" : "; ") + candidate + ": " + dlerror();
    }
    ThrowError(path, "needs OpenImageIO, whose module libibrdf_oiio.so could not be loaded (" + tried +
                         "; set IBRDF_OIIO_MODULE to its path)");
  }();
  return module;
}

}  // namespace

void PreloadImageModule() {
  try {
    Oiio("the OpenImageIO module");
  } catch (...) {
    // Reported by the first real use.
  }
}

namespace {

// Reads a plain PNG (8- or 16-bit grey or RGB, not interlaced, no transparency) with libpng, as
// OpenImageIO would: file values / (2^bits - 1) as float. Returns false, having read nothing, for any
// other PNG (those go through OpenImageIO). `image` null: the header only, into `spec`. `region`
// non-null: only its pixels are converted, and decoding stops after its last row (ReadImageRegion).
bool ReadPlainPng(const std::string& path, Image* image, ImageSpec* spec, const ImageRegion* region = nullptr) {
  FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) return false;
  png_byte signature[8];
  if (std::fread(signature, 1, 8, file) != 8 || png_sig_cmp(signature, 0, 8) != 0) {
    std::fclose(file);
    return false;
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::fclose(file);
    ThrowError(path, "cannot read image: out of memory");
  }
  std::vector<png_byte> row;
  // libpng reports errors by longjmp: nothing with a destructor may be created between here and the
  // reads below except `row` (declared above) and the pixels, which outlive the jump.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(file);
    ThrowError(path, "cannot decode image: corrupt PNG data");
  }
  png_init_io(png, file);
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const int bit_depth = png_get_bit_depth(png, info), colour = png_get_color_type(png, info);
  const bool plain = (colour == PNG_COLOR_TYPE_RGB || colour == PNG_COLOR_TYPE_GRAY) &&
                     (bit_depth == 8 || bit_depth == 16) && png_get_interlace_type(png, info) == PNG_INTERLACE_NONE &&
                     !png_get_valid(png, info, PNG_INFO_tRNS) && width > 0 && height > 0 && width <= (1u << 20) &&
                     height <= (1u << 20);
  const int channels = colour == PNG_COLOR_TYPE_RGB ? 3 : 1;
  if (plain && !image) *spec = {int(width), int(height), channels};
  if (!plain || !image) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(file);
    return plain;
  }
  if (bit_depth == 16) png_set_swap(png);  // native byte order (little-endian machines)
#ifdef PNG_IGNORE_ADLER32
  // A region that ends above the last row never reaches the stream's Adler-32 checksum (it follows
  // the last row), so computing it would be wasted; each chunk's CRC is still checked as it is read.
  if (region && region->y1 < int64_t(height)) png_set_option(png, PNG_IGNORE_ADLER32, PNG_OPTION_ON);
#endif
  png_read_update_info(png, info);
  image->width = int(width);
  image->height = int(height);
  image->channels = channels;
  image->pixels.resize(size_t(width) * height * channels);
  const size_t values = size_t(width) * channels;
  row.resize(values * (bit_depth / 8));
  // The rows and values converted: all, or the region's (clipped to the image). A PNG is one deflate
  // stream of rows filtered against the row above, so the rows before the region are decoded (not
  // converted) and those after it are never decoded.
  png_uint_32 row_begin = 0, row_end = height;
  size_t value_begin = 0, value_end = values;
  if (region) {
    const auto clip = [](int v, png_uint_32 size) { return png_uint_32(std::clamp<int64_t>(v, 0, int64_t(size))); };
    row_begin = clip(region->y0, height);
    row_end = std::max(row_begin, clip(region->y1, height));
    value_begin = size_t(clip(region->x0, width)) * channels;
    value_end = std::max(value_begin, size_t(clip(region->x1, width)) * channels);
  }
  for (png_uint_32 y = 0; y < row_end; ++y) {
    png_read_row(png, row.data(), nullptr);
    if (y < row_begin) continue;
    float* out = image->pixels.data() + size_t(y) * values;
    if (bit_depth == 16) {
      const uint16_t* in = reinterpret_cast<const uint16_t*>(row.data());
      for (size_t i = value_begin; i < value_end; ++i) out[i] = float(in[i]) * (1.0f / 65535.0f);
    } else {
      for (size_t i = value_begin; i < value_end; ++i) out[i] = float(row[i]) * (1.0f / 255.0f);
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(file);
  return true;
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

}  // namespace

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

namespace {

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
  RequireFile(path, "image");
  PhotoMetadata metadata;
  std::string error;
  if (!Oiio(path).read_metadata(path, IsRawExtension(path), &metadata, &error)) ThrowError(path, error);
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
  RequireFile(path, "image");
  ImageSpec spec;
  if (LowerExtension(path) == ".png" && ReadPlainPng(path, nullptr, &spec)) return spec;
  std::string error;
  if (!Oiio(path).read_spec(path, IsRawExtension(path), &spec, &error)) ThrowError(path, error);
  return spec;
}

Image ReadImage(const std::string& path) {
  Image image;
  ReadImage(path, &image);
  return image;
}

void ReadImage(const std::string& path, Image* image) {
  RequireFile(path, "image");
  if (LowerExtension(path) == ".png" && ReadPlainPng(path, image, nullptr)) {
    image->floating_point = false;
    return;
  }
  ReadImageThroughOpenImageIO(path, image);
}

void ReadImageRegion(const std::string& path, const ImageRegion& region, Image* image) {
  RequireFile(path, "image");
  if (LowerExtension(path) == ".png" && ReadPlainPng(path, image, nullptr, &region)) {
    image->floating_point = false;
    return;
  }
  ReadImageThroughOpenImageIO(path, image);
}

void ReadImageThroughOpenImageIO(const std::string& path, Image* image) {
  RequireFile(path, "image");
  std::string error;
  if (!Oiio(path).read(path, IsRawExtension(path), image, &error)) ThrowError(path, error);
}

void WriteImage(const std::string& path, const Image& image, PixelFormat format, const PhotoMetadata* metadata) {
  IBRDF_CHECK(image.pixels.size() == size_t(image.width) * image.height * image.channels);
  const OiioModule& oiio = Oiio(path);
  AtomicFile file(path);
  std::string error;
  if (!oiio.write(file.temporary_path(), image, static_cast<int>(format), metadata, &error)) ThrowError(path, error);
  // OpenImageIO 2.4 writes no EXIF into PNG files: ibrdf inserts the eXIf chunk itself.
  if (metadata && LowerExtension(path) == ".png") InsertPngExif(file.temporary_path(), *metadata);
  file.Commit();
}

}  // namespace ibrdf
