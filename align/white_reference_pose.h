// The white reference posed by its card's markers: the card carries a flat white
// patch (Spectralon) framed by ArUco markers whose corners are known in the card's frame
// (targets.white_reference; `ibrdf targets` prints the card). Each white-reference photo is posed from
// the platform's markers (their world corners after the bundle adjustment), the card from its own
// markers (PnP, then a robust refinement), and world_from_card = world_from_camera x camera_from_card;
// the photos' estimates are averaged. The result is the white reference's centre and normal in the
// world frame (what the light calibration, calibrate/white_reference_intensity.h, needs), with a covariance
// from the corners' geometry, so nobody types world coordinates.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "align/bundle_adjustment.h"
#include "align/markers.h"
#include "core/session.h"

namespace ibrdf {

struct WhiteReferencePoseOptions {
  double huber_px = 1.0;          // robust loss scale for the corners, pixels
  double corner_sigma_px = 0.05;  // corner noise for the covariance (a photo's own RMS when larger)
  int min_platform_markers = 2;   // platform markers a photo must see to be posed
  int min_card_markers = 2;       // card markers a photo must see for the card's pose
  double max_rms_px = 1.0;        // a photo whose platform or card corners fit worse is not used
  // Planar ambiguity of the card: a second pose of the card explaining its corners within this ratio of
  // the photo's own RMS (or corner_sigma_px) leaves the photo out.
  double ambiguity_ratio = 3.0;
  bool Check(std::string* why) const;
};

// One white-reference photo.
struct WhiteReferencePhotoPose {
  size_t photo = 0;  // index into calibration.white_reference.photos
  bool used = false;
  std::string dropped_reason;  // empty when used
  int platform_markers = 0;    // posed platform markers detected
  int card_markers = 0;        // card markers detected
  double platform_rms_px = 0.0;
  double card_rms_px = 0.0;
  double card_alternative_rms_px = -1.0;  // the card's planar second pose; < 0: none
  Rigid3d camera_from_world;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // this photo's estimate, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// The card's pose; reads as not posed until PoseWhiteReference returned.
struct WhiteReferencePose {
  bool posed = false;
  std::vector<WhiteReferencePhotoPose> photos;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();   // the patch's centre, world frame, metres
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // its front face's unit normal, world frame
  // Predicted covariance of the centre (3 x 3, m^2, world axes), and of the normal (3 x 3, in the
  // world; rank 2), from the corners' geometry (sigma^2 (J^T J)^-1 of both poses per photo,
  // propagated to the centre and normal, averaged over the photos).
  Eigen::Matrix3d center_covariance = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d normal_covariance = Eigen::Matrix3d::Zero();
  double normal_sigma_deg = 0.0;  // the normal's largest one-sigma tilt
  double spread_m = 0.0;          // largest distance of a photo's centre from the mean
  double spread_deg = 0.0;        // largest angle of a photo's normal from the mean
  // Per light (the session's order; lights without white-reference photos are absent): the relative
  // one-sigma error of the intensity the light calibration will measure, propagated from the pose's
  // covariance (r^2 / cos(theta_i) at the centre; the light's own position taken as exact).
  std::map<size_t, double> intensity_sigma_relative;
  double total_s = 0.0;
  // "white reference: posed by 4 card markers in 1 photo, centre sigma 0.05 mm, normal sigma 0.02 deg"
  std::string BriefReport() const;
};

// Poses the white reference of `session` (its targets.white_reference card and
// calibration.white_reference photos) against `world_markers`, the posed markers of the pose with their
// world corners (the bundle adjustment's). `camera` is the session's (after any calibration). Throws
// Error naming the photo or the manifest's field when the card cannot be posed: no photo sees enough
// platform and card markers, a photo is ambiguous, or the lights' photos disagree.
WhiteReferencePose PoseWhiteReference(const Session& session, const std::map<int, BundleMarker>& world_markers,
                                      const MarkerDictionary& dictionary,
                                      const WhiteReferencePoseOptions& options = WhiteReferencePoseOptions());

// alignment.json's "white_reference" block.
nlohmann::json ToJson(const WhiteReferencePose& pose);

}  // namespace ibrdf
