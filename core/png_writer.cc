#include "core/png_writer.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {

bool IsPlainPng(const std::string& path, const Image& image, PixelFormat format) {
  return LowerExtension(path) == ".png" && (image.channels == 1 || image.channels == 3) &&
         (format == PixelFormat::kUint8 || format == PixelFormat::kUint16) && image.width > 0 && image.height > 0;
}

void WritePlainPng(const std::string& path, const Image& image, PixelFormat format, PngEncoding encoding,
                   const PhotoMetadata* metadata) {
  if (!IsPlainPng(path, image, format)) {
    WriteImage(path, image, format, metadata);
    return;
  }
  IBRDF_CHECK(image.pixels.size() == size_t(image.width) * image.height * image.channels);
  const bool sixteen = format == PixelFormat::kUint16;
  const float levels = sixteen ? 65535.0f : 255.0f;
  // The file's rows, big-endian as PNG stores them (tests/synth/photo_png_test.cc and
  // tests/report/report_png_test.cc compare every 8- and 16-bit level and random values with WriteImage).
  const size_t values = image.pixels.size(), row_bytes = size_t(image.width) * image.channels * (sixteen ? 2 : 1);
  std::vector<png_byte> bytes(values * (sixteen ? 2 : 1));
  for (size_t i = 0; i < values; ++i) {
    const float v = image.pixels[i];
    const float scaled = (v > 0.0f ? std::min(v, 1.0f) : 0.0f) * levels;  // NaN: 0
    const auto level = static_cast<uint32_t>(scaled + 0.5f);
    if (sixteen) {
      bytes[2 * i] = png_byte(level >> 8);
      bytes[2 * i + 1] = png_byte(level & 0xff);
    } else {
      bytes[i] = png_byte(level);
    }
  }
  const std::string exif = metadata ? EncodeExif(*metadata) : std::string();

  AtomicFile file(path);
  FILE* out = std::fopen(file.temporary_path().c_str(), "wb");
  if (!out) ThrowError(path, "cannot write image: cannot create " + file.temporary_path());
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    std::fclose(out);
    ThrowError(path, "cannot write image: out of memory");
  }
  // libpng reports errors by longjmp: nothing with a destructor is created between here and the writes.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(out);
    ThrowError(path, "cannot write image: the PNG encoder failed (disk full?)");
  }
  png_init_io(png, out);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), sixteen ? 16 : 8,
               image.channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);  // as WriteImage asks OpenImageIO for
  if (encoding == PngEncoding::kAsOpenImageIo) {
    png_set_oFFs(png, info, 0, 0, PNG_OFFSET_PIXEL);  // as OpenImageIO writes it (the image's origin)
  } else {
    // libpng's adaptive per-row filter choice and zlib's general matching were most of the CPU; noise
    // defeats long matches and the dark background is runs.
    png_set_compression_strategy(png, Z_RLE);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  }
  if (!exif.empty()) {
    png_set_eXIf_1(png, info, png_uint_32(exif.size()),
                   const_cast<png_bytep>(reinterpret_cast<const png_byte*>(exif.data())));
  }
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) png_write_row(png, bytes.data() + size_t(y) * row_bytes);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(out) != 0) ThrowError(path, "cannot write image: closing " + file.temporary_path() + " failed");
  file.Commit();
}

}  // namespace ibrdf
