#include "calibrate/sphere_silhouettes.h"

#include <cstdio>
#include <utility>

#include "core/error.h"

namespace ibrdf {

SphereSilhouettes::SphereSilhouettes(const Session& session, bool fit, const SilhouetteFitOptions& options)
    : session_(session), fit_(fit), options_(options) {}

const SphereSilhouettes::Entry& SphereSilhouettes::For(size_t photo, bool* added) {
  IBRDF_CHECK(photo < session_.photos.size());
  IBRDF_CHECK(session_.photos[photo].camera_from_world.has_value());
  const Rigid3d& camera_from_world = *session_.photos[photo].camera_from_world;
  const std::string mask_path = session_.PhotoMaskPath(photo);
  const Eigen::Quaterniond& q = camera_from_world.rotation;
  const Eigen::Vector3d& t = camera_from_world.translation;
  char pose[256];
  std::snprintf(pose, sizeof(pose), "|%.12g %.12g %.12g %.12g|%.12g %.12g %.12g", q.w(), q.x(), q.y(), q.z(), t.x(),
                t.y(), t.z());
  const std::string key = mask_path + pose;
  const auto found = entries_.find(key);
  *added = found == entries_.end();
  if (!*added) return found->second;
  Entry entry;
  if (!mask_path.empty()) entry.mask = ReadPixelMask(mask_path, session_.camera.width, session_.camera.height);
  if (fit_) {
    if (mask_path.empty()) {
      ThrowError(session_.PhotoPath(photo),
                 "fitting the sphere's silhouette needs a mask (the session's \"mask\" or the photo's); or take "
                 "the session's sphere as known (--known-sphere)");
    }
    entry.silhouette = FitSphereSilhouette(session_.camera, MaskEdgePoints(entry.mask), options_);
    if (!entry.silhouette.fitted) ThrowError(mask_path, "no sphere silhouette: " + entry.silhouette.reason);
  } else {
    entry.silhouette = SphereSilhouette::FromCenter(session_.camera, camera_from_world * session_.sample.center,
                                                    session_.sample.radius);
    if (!entry.silhouette.fitted) {
      ThrowError(session_.manifest_path + ": /sample", entry.silhouette.reason + " of " + session_.PhotoPath(photo));
    }
  }
  return entries_.emplace(key, std::move(entry)).first->second;
}

}  // namespace ibrdf
