#include "report/report_png.h"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "core/error.h"
#include "core/file_util.h"

namespace ibrdf {

void WriteReportPng(const std::string& path, const Image& image) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".png" || (image.channels != 1 && image.channels != 3) || image.width <= 0 || image.height <= 0) {
    WriteImage(path, image, PixelFormat::kUint8);
    return;
  }
  IBRDF_CHECK(image.pixels.size() == size_t(image.width) * image.height * image.channels);
  // OpenImageIO's conversion: v * 255 + 0.5 in float arithmetic, truncated (the same bytes for every
  // level and 3 M random values, tests/report/report_png_test.cc).
  std::vector<png_byte> bytes(image.pixels.size());
  for (size_t i = 0; i < bytes.size(); ++i) {
    const float v = image.pixels[i];
    const float scaled = (v > 0.0f ? std::min(v, 1.0f) : 0.0f) * 255.0f;  // NaN: 0
    bytes[i] = static_cast<png_byte>(static_cast<uint32_t>(scaled + 0.5f));
  }
  const size_t row_bytes = size_t(image.width) * image.channels;

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
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8,
               image.channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_oFFs(png, info, 0, 0, PNG_OFFSET_PIXEL);  // as OpenImageIO writes it (the image's origin)
  png_set_compression_level(png, 1);                // as WriteImage asks OpenImageIO for
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y) png_write_row(png, bytes.data() + size_t(y) * row_bytes);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fclose(out) != 0) ThrowError(path, "cannot write image: closing " + file.temporary_path() + " failed");
  file.Commit();
}

}  // namespace ibrdf
