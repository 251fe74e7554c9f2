// The align stage (the paper's section 3.2, in part): camera poses from coded targets, by a bundle
// adjustment over every photo's marker corners (align/bundle_adjustment.h) in which markers of known
// layout stay fixed and markers of unknown layout are rigid squares whose poses are estimated; the
// light's position from the markers attached to it (align/light_fit.h); a sphere sample's centre and
// radius from its silhouettes (align/sphere_fit.h); a cylinder's centre and axis from the markers fixed
// to it (align/cylinder_fit.h); AlignSession runs these steps in turn. A photo whose pose is unreliable
// (too few markers, a high residual, a pose its corners determine poorly, or a planar pose ambiguity)
// is dropped with a reason, never used.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "align/bundle_adjustment.h"
#include "align/cylinder_fit.h"
#include "align/light_fit.h"
#include "align/sphere_fit.h"
#include "align/white_reference_pose.h"
#include "core/session.h"

namespace ibrdf {

struct AlignOptions {
  int min_markers_per_image = 2;  // fewer posed markers seen (corners of known or estimated layout): dropped
  double max_image_rms_px = 1.0;  // reprojection RMS above this: the photo is dropped
  double huber_px = 1.0;          // robust loss scale for marker corners, pixels
  // Reliability of a pose from its corners' geometry (EstimatePoseUncertainty), for corners measured
  // to corner_sigma_px (or the photo's own RMS, if larger): a photo whose camera position or rotation
  // is predicted worse than these (one sigma) is dropped. Nearly collinear markers, one small marker or
  // far-away markers fail here, whatever their count.
  double corner_sigma_px = 0.05;
  double max_position_sigma_m = 0.35e-3;
  double max_rotation_sigma_deg = 0.035;
  // Planar pose ambiguity: a photo whose coplanar corners are explained by a second, distinct pose
  // with a reprojection RMS below ambiguity_ratio x max(its own RMS, corner_sigma_px) is dropped.
  double ambiguity_ratio = 3.0;
  bool fit_sphere = true;          // refine a sphere sample's centre and radius from silhouettes
  bool fit_cylinder = true;        // a cylinder's centre and axis from its markers (targets.sample)
  bool fit_light = true;           // the light's position from its markers, when the session has them
  // The white reference's centre and normal from its card's markers, when the session has them
  // (targets.white_reference) and white-reference photos (align/white_reference_pose.h).
  bool pose_white_reference = true;
  BundleAdjustmentOptions bundle;  // huber_px is taken from above
  CylinderFitOptions cylinder;     // the cylinder fit (align/cylinder_fit.h)
  SphereFitOptions sphere;         // the sphere fit (align/sphere_fit.h)
  LightFitOptions light;           // the light fit (align/light_fit.h); huber_px is taken from above
  WhiteReferencePoseOptions white_reference;  // huber_px and corner_sigma_px are taken from above
  bool Check(std::string* why) const;
};

struct ImageAlignment {
  size_t photo = 0;
  bool used = false;
  std::string dropped_reason;     // empty when used
  int markers = 0;                // markers of the pose (known, unknown layout, sample) detected and posed
  int light_markers = 0;          // markers of the light detected
  int ignored_markers = 0;        // detections of ids in no target list (or duplicated)
  int outlier_corners = 0;        // corners left out of the final solve (partly hidden markers)
  double rms_px = 0.0;            // reprojection RMS of the inlier corners after the bundle adjustment
  double position_sigma_m = 0.0;  // predicted standard deviations of the pose (EstimatePoseUncertainty)
  double rotation_sigma_deg = 0.0;
  double alternative_rms_px = -1.0;  // RMS of the planar second pose (AlternativePoseRms); < 0: none
  Rigid3d camera_from_world;         // photos that see light markers: after the joint refinement with them
};

struct MarkerResidual {
  int id = -1;
  std::string kind;      // "reference" (known layout), "unknown" (estimated) or "sample"
  int observations = 0;  // used photos that see it
  double rms_px = 0.0;
  std::array<Eigen::Vector3d, 4> corners;  // world frame (estimated, for "unknown" and "sample")
};

// What the stage did. AlignSession throws Error for bad input (options, targets, photos) and when no
// photo could be posed; a returned result always has at least one used photo.
struct AlignResult {
  Session session;  // the input session with poses (and sphere) replaced; dropped photos removed
  std::vector<ImageAlignment> images;
  std::vector<MarkerResidual> markers;
  SphereFit sphere;
  CylinderFit cylinder;
  LightFit light;
  WhiteReferencePose white_reference;  // posed only with the card's markers and white-reference photos
  BundleAdjustmentSummary bundle;
  // The scanned mesh was registered to the markers after the alignment (align_stage's step): its
  // world_from_mesh is new, not the sample's pose as given.
  bool mesh_registered = false;
  double rms_px = 0.0;  // over all corners of used photos
  double total_s = 0.0;
  std::string BriefReport() const;
};

// Aligns a session whose "targets" block gives markers of known layout, of unknown layout (with one
// origin marker when none is known), or both, and optionally the light's and the sample's markers.
// Every photo is posed, target photos (role "targets") included; only measurement photos serve the
// silhouette fits. The sample's centre and radius in the session serve as the starting guess of the
// sphere fit. In the aligned session, markers of unknown layout that were posed join the reference
// layout with their estimated corners. With the white reference's card markers (targets.white_reference),
// the white-reference photos are posed and the aligned session's white reference gets the card's
// centre and normal (replacing any stated ones).
AlignResult AlignSession(const Session& session, const AlignOptions& options);

nlohmann::json ToJson(const AlignResult& result);

}  // namespace ibrdf
