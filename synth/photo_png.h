// Synth's photos written as PNG with libpng directly: 8- or 16-bit grey or RGB, unfiltered rows, deflate
// level 1 with run-length matches only, the EXIF block in an eXIf chunk. The same pixels OpenImageIO's
// writer (core WriteImage) stores, in a quarter of its CPU time (libpng's adaptive per-row filter choice
// and zlib's general matching were most of it) and in files no larger (noise defeats long matches; the
// dark background is runs).
#pragma once

#include <string>

#include "core/image_io.h"

namespace ibrdf {

// True when WritePhotoPng writes `path` itself: a .png of 1 or 3 channels stored as kUint8 or kUint16.
bool IsPlainPhotoPng(const std::string& path, const Image& image, PixelFormat format);

// Writes `image` (values in [0, 1], clamped; NaN as 0) atomically, each value as v * (2^bits - 1) rounded
// half up (OpenImageIO's conversion), and `metadata` (when not null) as an eXIf chunk that ReadPhotoMetadata reads
// back. Other files (IsPlainPhotoPng false) go through WriteImage. Throws Error naming the file.
void WritePhotoPng(const std::string& path, const Image& image, PixelFormat format,
                   const PhotoMetadata* metadata = nullptr);

}  // namespace ibrdf
