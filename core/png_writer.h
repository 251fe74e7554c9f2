// Plain PNGs (8- or 16-bit grey or RGB) written with libpng directly, so that a stage writing them never
// loads OpenImageIO's ~260 libraries (half a second of CPU). Two encodings: byte for byte the file core
// WriteImage writes through OpenImageIO (the report's images), or a fast one for synth's photos (the same
// pixels in a quarter of the CPU). docs/decisions.md, "One PNG writer for synth and the report".
#pragma once

#include <string>

#include "core/image_io.h"

namespace ibrdf {

// How WritePlainPng encodes the rows; both store the same pixels.
enum class PngEncoding {
  // OpenImageIO's file: deflate level 1, libpng's adaptive row filters, an oFFs chunk (the image's origin).
  kAsOpenImageIo,
  // Unfiltered rows, deflate level 1 with run-length matches only (Z_RLE): on the demo's 20 photos 0.43 s of
  // CPU and 15.7 MB against 1.87 s and 15.9 MB through OpenImageIO; decoded as fast.
  kFast,
};

// True when WritePlainPng writes `path` itself: a .png of 1 or 3 channels stored as kUint8 or kUint16.
bool IsPlainPng(const std::string& path, const Image& image, PixelFormat format);

// Writes `image` (values in [0, 1], clamped; NaN as 0) atomically, each value as v * (2^bits - 1) + 0.5 in
// float arithmetic, truncated (OpenImageIO's conversion: ties such as a 12-bit level's 37128.5 round up),
// and `metadata` (when not null) as an eXIf chunk that ReadPhotoMetadata reads back. Other files
// (IsPlainPng false) go through WriteImage. Throws Error naming the file.
void WritePlainPng(const std::string& path, const Image& image, PixelFormat format, PngEncoding encoding,
                   const PhotoMetadata* metadata = nullptr);

}  // namespace ibrdf
