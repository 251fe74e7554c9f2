// A photo's file values to linear signal, the one way every stage does it outside the derenderer's
// own per-pixel loop (radiometry/radiance_image.h, which reads the same flat field): the session's
// response inverted, the black level subtracted (clamped at 0), divided by the flat field, and
// optionally by the photo's exposure time and gain (then in the session's radiance unit).
// docs/radiometry.md states the chain.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/image_io.h"
#include "core/session.h"

namespace ibrdf {

// The inverse of a session's flat field, 3 floats per pixel (row-major, the camera's size).
struct FlatField {
  std::vector<float> inverse;
};

// Reads and checks the session's flat-field image (its size against the camera, positive finite
// values; a warning when its centre is far from 1); nullptr when the session has none. Cached per
// file (path, size, modification time), so a stage that asks once per photo decodes it once.
// Throws Error naming the image and the manifest's field.
std::shared_ptr<const FlatField> LoadFlatField(const Session& session);

// The file value at which a channel of `image` counts as clipped: the session's saturation_level when
// its manifest states one; otherwise 1.0 (full scale) for integer files and +infinity for
// floating-point files (an HDR render or merged EXR has no full scale: clipping it at 1.0 would throw
// away every highlight).
double SaturationLevel(const RadiometrySpec& radiometry, const Image& image);

// Per pixel of `image` (its file values, before LinearizeImage), 1 where one of its colour channels (the
// first three; a grey image's one) reaches SaturationLevel, 0 elsewhere: the clipping test of the
// derenderer's chain (radiance_image.h, kPixelSaturated) for a stage that reads a photo whole.
std::vector<uint8_t> SaturatedPixels(const RadiometrySpec& radiometry, const Image& image);

// Linearizes `image` (photo `photo` of the session, as ReadImage decoded it) in place by the chain
// above. Grey images use the mean of the flat field's channels; channels past the third (alpha) are
// left as they are. Throws Error naming the photo if its size is not the camera's while a flat field
// is given.
void LinearizeImage(const Session& session, size_t photo, Image* image, bool divide_by_exposure = false);

}  // namespace ibrdf
