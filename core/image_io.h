// Image I/O through OpenImageIO (and libpng for plain PNGs): every format it reads (8/16-bit PNG and TIFF, EXR, camera
// RAW ...) into float pixels, file values normalized to [0, 1] for integer formats. Linearization is the session's
// business (core/radiometry.h), except for camera RAW, which LibRaw decodes here to linear camera RGB: the file's
// black level subtracted and its white level scaled to 1.0, demosaiced, with no white balance and no colour matrix
// (docs/radiometry.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace ibrdf {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // interleaved, row-major: pixels[(y * width + x) * channels + c]
  // The file stores floating-point values (EXR, float or half TIFF): no full scale, so no saturation
  // unless the session states one. Set by ReadImage.
  bool floating_point = false;

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

// A rectangle of pixels [x0, x1) x [y0, y1).
struct ImageRegion {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// As ReadImage(path, image), for a caller that reads only the pixels inside `region`: `image` gets the
// file's full size, the region's pixels (clipped to the image) hold exactly ReadImage's values, the
// others are unspecified. Plain PNGs convert only the region's pixels and stop decoding after its last
// row (so damage to the file after that row goes unnoticed); other formats are decoded whole.
void ReadImageRegion(const std::string& path, const ImageRegion& region, Image* image);

// ReadImage through OpenImageIO whatever the file (the reference for the PNG fast path).
void ReadImageThroughOpenImageIO(const std::string& path, Image* image);

// The size and channel count without decoding the pixels.
struct ImageSpec {
  int width = 0, height = 0, channels = 0;
};
ImageSpec ReadImageSpec(const std::string& path);

// What a camera writes into a photo's metadata (EXIF), as OpenImageIO reads it. Absent fields are
// those the file does not carry.
struct PhotoMetadata {
  std::optional<double> exposure_s;          // EXIF ExposureTime, seconds
  std::optional<double> iso;                 // EXIF PhotographicSensitivity (ISOSpeedRatings)
  std::optional<double> f_number;            // EXIF FNumber
  std::optional<double> focal_length_mm;     // EXIF FocalLength
  std::optional<double> focal_length_35mm;   // EXIF FocalLengthIn35mmFilm, millimetres
  std::optional<double> pixels_per_mm;       // EXIF FocalPlaneXResolution in its unit, as pixels per mm
  std::string make, model;                   // EXIF Make, Model (empty when absent)
  std::string date_time;                     // EXIF DateTimeOriginal or DateTime, "YYYY:MM:DD HH:MM:SS"
  int width = 0, height = 0, channels = 0;   // the decoded image's size
  bool floating_point = false;               // float or half pixels (EXR, float TIFF)
  int bits = 0;                              // bits per stored sample (0 when floating point)
  bool raw = false;                          // a camera RAW file (decoded through LibRaw)
};

// Reads the header and metadata without decoding the pixels. Throws Error naming the file.
PhotoMetadata ReadPhotoMetadata(const std::string& path);

// Loads the OpenImageIO module now: WriteImage and the readers of other formats than plain PNG load it
// on first use (about half a second of CPU for its ~260 libraries), so a caller can pay that on a thread
// of its own beside other work (the report). Errors are left for the first real use to report.
void PreloadImageModule();

// Writes an image atomically; the format follows the extension (.png, .tif, .exr ...). Integer formats
// take values in [0, 1], clamped and rounded. With `metadata`, its set fields are written as EXIF (PNG:
// an eXIf chunk; TIFF, JPEG: EXIF tags; EXR: header attributes), so ReadPhotoMetadata reads them back.
void WriteImage(const std::string& path, const Image& image, PixelFormat format,
                const PhotoMetadata* metadata = nullptr);

// The EXIF block WriteImage puts into a PNG's eXIf chunk (a little-endian TIFF structure of the set
// fields of `metadata`), for a PNG writer of its own (synth's photos).
std::string EncodeExif(const PhotoMetadata& metadata);

// True for file extensions OpenImageIO's RAW reader handles (.cr2, .nef, .arw, .dng ...).
bool IsRawExtension(const std::string& path);

}  // namespace ibrdf
