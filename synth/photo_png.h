// Synth's photos written as PNG with libpng directly: 8- or 16-bit grey or RGB, no filter, deflate level 1,
// the EXIF block in an eXIf chunk. The same pixels OpenImageIO's writer (core WriteImage) stores for
// synth's quantized signals, without loading OpenImageIO's ~260 libraries (half a second of CPU) and
// without libpng's adaptive per-row filter choice (a third of the encoding's time); files about 3 %
// larger, decoded as fast or faster.
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
