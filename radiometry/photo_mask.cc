#include "radiometry/photo_mask.h"

#include <string>

#include "core/error.h"
#include "core/image_io.h"

namespace ibrdf {

std::vector<uint8_t> ReadGroupMask(const Session& session, const std::vector<size_t>& group) {
  std::vector<uint8_t> usable;
  std::string previous;  // a bracket's photos usually share one mask: read it once
  for (size_t i : group) {
    const std::string path = session.PhotoMaskPath(i);
    if (path.empty() || path == previous) continue;
    previous = path;
    const Image mask = ReadImage(path);
    if (mask.width != session.camera.width || mask.height != session.camera.height) {
      ThrowError(path, "mask is " + std::to_string(mask.width) + "x" + std::to_string(mask.height) + " but its photo " +
                           session.PhotoPath(i) + " is " + std::to_string(session.camera.width) + "x" +
                           std::to_string(session.camera.height) + " (" + session.manifest_path + ": /photos/" +
                           std::to_string(i) + ")");
    }
    const size_t n = size_t(mask.width) * mask.height;
    if (usable.empty()) usable.assign(n, 1);
    for (size_t p = 0; p < n; ++p) {
      bool any = false;
      for (int c = 0; c < mask.channels; ++c) any |= mask.pixels[p * mask.channels + c] != 0.0f;
      if (!any) usable[p] = 0;
    }
  }
  return usable;
}

}  // namespace ibrdf
