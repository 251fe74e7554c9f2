// Masks (docs/session-format.md, version 2): an image per photo, or one for the whole session, whose
// non-zero pixels are usable; the derenderer never samples a pixel outside it and counts such pixels
// under their own rejection reason ("masked"). A mask is the photo's size, any channel count and
// format OpenImageIO reads; a pixel is usable when any of its channels is non-zero.
#pragma once

#include <cstdint>
#include <vector>

#include "core/session.h"

namespace ibrdf {

// The usable pixels of one exposure group (session.photos indices; radiometry/radiance_image.h): one
// byte per pixel, row-major, 1 where every photo of the group that has a mask (its own, or the
// session's default) marks the pixel usable, 0 elsewhere. Empty when no photo of the group has a mask.
// Throws Error naming the mask for an unreadable file, and naming both the mask and the photo for a
// mask whose size differs from the camera's.
std::vector<uint8_t> ReadGroupMask(const Session& session, const std::vector<size_t>& group);

}  // namespace ibrdf
