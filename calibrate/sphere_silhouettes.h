// The silhouette of a session's sphere (a mirror ball, a diffuse sphere) and the usable-pixel mask of
// each of its photos, found once per mask and pose (a fixed camera needs one): fitted to the mask's
// edge (mirror_sphere.h, MaskEdgePoints and FitSphereSilhouette) or, without a fit, the session's
// sphere taken as exact. The mirror-sphere and diffuse-sphere calibrations share it.
#pragma once

#include <map>
#include <string>

#include "calibrate/mirror_sphere.h"
#include "core/session.h"

namespace ibrdf {

class SphereSilhouettes {
 public:
  struct Entry {
    SphereSilhouette silhouette;
    PixelMask mask;  // empty (width 0) where the photo has no mask
  };

  // `fit`: fit each silhouette to its mask's edge; otherwise the session's sample centre and radius.
  SphereSilhouettes(const Session& session, bool fit, const SilhouetteFitOptions& options);

  // The entry of photo `photo` (session.photos), which must have a camera_from_world pose; `added` is
  // set to whether this call found it (the first photo of its mask and pose). Throws Error naming the
  // photo for a fit without a mask, the mask for a silhouette that cannot be fitted, and the manifest's
  // sample for a sphere that is not in front of the camera.
  const Entry& For(size_t photo, bool* added);

 private:
  const Session& session_;
  bool fit_;
  SilhouetteFitOptions options_;
  std::map<std::string, Entry> entries_;  // by mask path and pose
};

}  // namespace ibrdf
