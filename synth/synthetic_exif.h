// The EXIF a real camera would write into a synthetic photo (a synthetic capture left as a
// camera leaves it, for `ibrdf session init`): exposure time, ISO (100 x the photo's gain), f-number,
// focal length in millimetres for a sensor of kPixelPitchMm pixels, its 35 mm equivalent, the focal
// plane resolution, make "ibrdf", model "synth" and a capture time: 10 s between poses, 1 s between
// the exposures of one bracket (as a camera's bracketing burst).
#pragma once

#include <cstddef>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/session.h"

namespace ibrdf {

// The synthetic sensor's pixel pitch, millimetres (a typical 4.5 micrometre pixel).
constexpr double kSyntheticPixelPitchMm = 0.0045;

// The metadata of `photo`, taken after session.photos[0 .. index) with the session's camera (index may
// be photos.size(): a photo after the session's, e.g. the white reference).
PhotoMetadata SyntheticPhotoMetadata(const Session& session, const PhotoSpec& photo, size_t index);

}  // namespace ibrdf
