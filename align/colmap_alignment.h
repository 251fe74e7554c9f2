// A COLMAP sparse model brought into the metric target frame: COLMAP's poses are
// right up to a similarity (its frame, scale and origin are arbitrary); the photos that the coded
// targets posed fix it. The similarity world_from_colmap maps COLMAP's camera centres onto the
// target-based ones (Umeyama's closed form, in double, inside an exhaustive or sampled consensus over
// triples of photos so that a misregistered image cannot pull it), and every image COLMAP registered
// then gets a metric pose in the target frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>

#include "align/colmap_model.h"
#include "core/rigid3.h"
#include "core/session.h"

namespace ibrdf {

// y = scale * rotation * x + translation (COLMAP's Sim3d), named target_from_source.
struct Similarity3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return scale * (rotation * x) + translation; }
  Similarity3d Inverse() const;
  // The pose of a camera given in the source frame (camera_from_source, COLMAP's scale) as a metric
  // camera_from_target: same optical centre and axes, the translation in the target's units.
  Rigid3d TransformPose(const Rigid3d& camera_from_source) const;
  // Umeyama's least-squares similarity taking `source` onto `target` (columns are points; >= 3, not
  // collinear). Throws Error (naming `where`) on degenerate input.
  static Similarity3d Estimate(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                               const std::string& where);
};

struct ColmapAlignmentOptions {
  int min_images = 3;                   // photos posed both ways needed for the similarity
  double max_center_error_m = 0.01;     // a camera centre further than this from its target-based one is an outlier
  double max_rotation_error_deg = 1.0;  // likewise for the camera's orientation
  int max_triples = 20000;              // consensus: every triple of photos up to this many, else a seeded sample
  bool Check(std::string* why) const;
};

// One photo of the session and what COLMAP and the targets say about it.
struct ColmapPhotoMatch {
  std::string photo;                   // the session's file name (as in session.json)
  int64_t image_id = -1;               // COLMAP's image, -1 if COLMAP did not register it
  std::optional<Rigid3d> target_pose;  // camera_from_world from the coded targets, if posed
  std::optional<Rigid3d> metric_pose;  // COLMAP's pose through the similarity (set after success)
  bool inlier = false;                 // used for the final similarity
  double center_error_m = 0.0;         // |C_target - S * C_colmap|, where both exist
  double rotation_error_deg = 0.0;     // angle between the two orientations, where both exist
};

struct ColmapAlignment {
  bool success = false;
  Similarity3d world_from_colmap;
  std::vector<ColmapPhotoMatch> photos;  // in the session's order
  int matched = 0;                       // photos COLMAP registered
  int both = 0;                          // of those, posed by the targets too
  int inliers = 0;                       // of those, agreeing with the similarity
  int unmatched_images = 0;              // COLMAP images named like no photo of the session
  double rms_center_error_m = 0.0;       // over the inliers
  double max_center_error_m = 0.0;       // over the inliers
  double rms_rotation_error_deg = 0.0;   // over the inliers
  std::string BriefReport() const;
};

// Matches the model's images to the photos by name (the photo's path relative to the session, then
// its file name if that is unique in the model) and estimates world_from_colmap from the photos posed
// both ways. `photo_files` and `target_poses` run in parallel (target_poses[i] empty where the targets
// did not pose photo i). Throws Error (naming `model_directory`) when fewer than options.min_images
// photos are posed both ways or no consistent similarity exists.
ColmapAlignment AlignColmapModel(const ColmapModel& model, const std::vector<std::string>& photo_files,
                                 const std::vector<std::optional<Rigid3d>>& target_poses,
                                 const ColmapAlignmentOptions& options, const std::string& model_directory);

// The one camera that every matched image of `model` uses, if there is one (nullptr otherwise).
const Camera* SharedColmapCamera(const ColmapModel& model, const ColmapAlignment& alignment);

nlohmann::json ToJson(const ColmapAlignment& alignment);

// The target-aligned session `target_aligned` with COLMAP's poses merged in, photo by photo of `input`
// (the session that was aligned; `alignment` was made from its photos): a photo COLMAP registered gets
// its metric pose, except one whose COLMAP pose disagrees with its target-based pose (not an inlier),
// which keeps the target-based one; a photo COLMAP lacks keeps its target-based pose; a photo neither
// posed is left out. The camera becomes COLMAP's shared camera (SharedColmapCamera) when it has the
// session's size, unless `keep_camera` (calibrated intrinsics). Logs each pose or camera kept.
Session MergeColmapPoses(const Session& input, const Session& target_aligned, const ColmapModel& model,
                         const ColmapAlignment& alignment, bool keep_camera);

}  // namespace ibrdf
