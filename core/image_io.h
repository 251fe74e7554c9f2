// Image I/O through OpenImageIO (and libpng for plain PNGs): every format it reads (8/16-bit PNG and TIFF, EXR, camera
// RAW ...) into float pixels, file values normalized to [0, 1] for integer formats. Linearization is the session's
// business (core/radiometry.h), except for camera RAW, which is decoded to a linear colour space here, since
// OpenImageIO's RAW reader would otherwise apply an sRGB curve.
#pragma once

#include <string>
#include <vector>

namespace ibrdf {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // interleaved, row-major: pixels[(y * width + x) * channels + c]

  Image() = default;
  Image(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c, 0.0f) {}
  float& at(int x, int y, int c) { return pixels[(size_t(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return pixels[(size_t(y) * width + x) * channels + c]; }
};

// Rec. 709 luminance at a continuous pixel position (pixel centres at +0.5, COLMAP's convention),
// interpolated bilinearly between pixel centres; the first channel of a grey image. NaN where the
// 2 x 2 neighbourhood leaves the image.
double BilinearLuminance(const Image& image, double x, double y);

// Storage formats for WriteImage.
enum class PixelFormat { kUint8, kUint16, kHalf, kFloat };

// Reads any image OpenImageIO can; throws Error naming the file on failure.
Image ReadImage(const std::string& path);

// As ReadImage, into `image`, whose pixel buffer is reused when it is large enough (a loop over photos
// of one size allocates once). Plain PNGs (8- or 16-bit grey or RGB, no alpha, palette, transparency
// or interlacing) are decoded with libpng, to the same floats; everything else, and every write, goes
// through OpenImageIO, loaded on first use (the module libibrdf_oiio.so: OpenImageIO's 260 shared
// libraries are not loaded by a process that never needs them).
void ReadImage(const std::string& path, Image* image);

// ReadImage through OpenImageIO whatever the file (the reference for the PNG fast path).
void ReadImageThroughOpenImageIO(const std::string& path, Image* image);

// The size and channel count without decoding the pixels.
struct ImageSpec {
  int width = 0, height = 0, channels = 0;
};
ImageSpec ReadImageSpec(const std::string& path);

// Writes an image atomically; the format follows the extension (.png, .tif, .exr ...). Integer formats
// take values in [0, 1], clamped and rounded.
void WriteImage(const std::string& path, const Image& image, PixelFormat format);

// True for file extensions OpenImageIO's RAW reader handles (.cr2, .nef, .arw, .dng ...).
bool IsRawExtension(const std::string& path);

}  // namespace ibrdf
