#include "core/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
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

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// The OpenImageIO module (core/image_io_oiio.cc), loaded on first use.
struct OiioModule {
  bool (*read_spec)(const std::string&, bool, ImageSpec*, std::string*) = nullptr;
  bool (*read)(const std::string&, bool, Image*, std::string*) = nullptr;
  bool (*write)(const std::string&, const Image&, int, std::string*) = nullptr;
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
        m.write = reinterpret_cast<decltype(m.write)>(dlsym(handle, "IbrdfOiioWrite"));
        IBRDF_CHECK(m.read_spec && m.read && m.write) << candidate << " lacks the image functions";
        return m;
      }
      tried += (tried.empty() ? "" : "; ") + candidate + ": " + dlerror();
    }
    ThrowError(path, "needs OpenImageIO, whose module libibrdf_oiio.so could not be loaded (" + tried +
                         "; set IBRDF_OIIO_MODULE to its path)");
  }();
  return module;
}

// Reads a plain PNG (8- or 16-bit grey or RGB, not interlaced, no transparency) with libpng, as
// OpenImageIO would: file values / (2^bits - 1) as float. Returns false, having read nothing, for any
// other PNG (those go through OpenImageIO). `image` null: the header only, into `spec`.
bool ReadPlainPng(const std::string& path, Image* image, ImageSpec* spec) {
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
  png_read_update_info(png, info);
  image->width = int(width);
  image->height = int(height);
  image->channels = channels;
  image->pixels.resize(size_t(width) * height * channels);
  const size_t values = size_t(width) * channels;
  row.resize(values * (bit_depth / 8));
  float* out = image->pixels.data();
  for (png_uint_32 y = 0; y < height; ++y, out += values) {
    png_read_row(png, row.data(), nullptr);
    if (bit_depth == 16) {
      const uint16_t* in = reinterpret_cast<const uint16_t*>(row.data());
      for (size_t i = 0; i < values; ++i) out[i] = float(in[i]) * (1.0f / 65535.0f);
    } else {
      for (size_t i = 0; i < values; ++i) out[i] = float(row[i]) * (1.0f / 255.0f);
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(file);
  return true;
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
  if (LowerExtension(path) == ".png" && ReadPlainPng(path, image, nullptr)) return;
  ReadImageThroughOpenImageIO(path, image);
}

void ReadImageThroughOpenImageIO(const std::string& path, Image* image) {
  RequireFile(path, "image");
  std::string error;
  if (!Oiio(path).read(path, IsRawExtension(path), image, &error)) ThrowError(path, error);
}

void WriteImage(const std::string& path, const Image& image, PixelFormat format) {
  IBRDF_CHECK(image.pixels.size() == size_t(image.width) * image.height * image.channels);
  const OiioModule& oiio = Oiio(path);
  AtomicFile file(path);
  std::string error;
  if (!oiio.write(file.temporary_path(), image, static_cast<int>(format), &error)) ThrowError(path, error);
  file.Commit();
}

}  // namespace ibrdf
