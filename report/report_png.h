// The report's 8-bit PNGs (the photo, model renders, spheres, light thumbnails) written with libpng
// directly (core/png_writer.h), byte for byte the files core WriteImage writes through OpenImageIO, so
// the report never loads OpenImageIO's ~260 libraries (half a second of CPU) for a session of plain PNG
// photos.
#pragma once

#include <string>

#include "core/image_io.h"
#include "core/png_writer.h"

namespace ibrdf {

// Writes `image` (values in [0, 1], clamped; NaN as 0) atomically as an 8-bit PNG, the same bytes as
// WriteImage(path, image, PixelFormat::kUint8) for a .png of 1 or 3 channels; any other file or channel
// count goes through WriteImage. Throws Error naming the file.
inline void WriteReportPng(const std::string& path, const Image& image) {
  WritePlainPng(path, image, PixelFormat::kUint8, PngEncoding::kAsOpenImageIo);
}

}  // namespace ibrdf
