// The report's Acquisition thumbnails: each measurement photo (an even subset of them), small, with the
// sample's outline as the session's poses and camera model (distortion included) put it drawn over it in
// green, so a pose, sample fit or mesh registration that is off shows as an outline beside the object.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/image_io.h"
#include "core/rigid3.h"
#include "core/session.h"
#include "report/photo_comparison.h"
#include "report/photo_statistics.h"

namespace ibrdf {

struct ScanMesh;

struct AcquisitionThumbnailOptions {
  int max_photos = 24;       // at most this many measurement photos, chosen evenly over the session's order
  int size_px = 200;         // longest side of a thumbnail, pixels
  int outline_points = 360;  // points per projected circle (sphere limb, cylinder rim) or line

  bool Check(std::string* why) const;
};

// The sample's outline in photo pixels (COLMAP's convention, core/camera.h) seen by a camera at
// `camera_from_world`, as polylines (each drawn segment joins consecutive points):
//  sphere: the limb, the circle of tangency of the cone from the camera centre (centre c + R^2/d u,
//    radius R sqrt(1 - R^2/d^2), u the unit vector from c to the camera, d the distance), one closed line;
//  cylinder: the two rim circles and the two limb lines (the generators whose normal is perpendicular
//    to the view ray: at angle +-acos(R/d) from the camera's direction across the axis);
//  mesh: each silhouette edge (between a face towards the camera and one away; not boundary edges,
//    which on a scan mesh are mostly seams between scans) as a two-point line; `mesh` is the sample's
//    mesh in its own frame (world_from_mesh maps it), null for other kinds.
// Points behind the camera end a polyline. Empty when the camera is inside the sphere or cylinder.
std::vector<std::vector<Eigen::Vector2d>> SampleOutline(const Session& session, const Rigid3d& camera_from_world,
                                                        const ScanMesh* mesh, int outline_points = 360);

// Shrinks `box` of `photo` by an integer box filter (the smallest step that fits it in `size` pixels on
// a side) to an RGB image; `step` (optional) gets the step: thumbnail pixel (x, y) covers photo pixels
// box.x0 + x * step ... + step - 1.
Image ShrinkRegion(const Image& photo, const PixelBox& box, int size, int* step = nullptr);

// Writes `tmp_dir`/acquisition/NNN.png (NNN the photo index) for up to options.max_photos measurement
// photos of `session` (linearized, cropped to the outline's and the samples' box with a margin, shrunk,
// tone-mapped on one scale for all, the median of ToneMap's own scales, the outline in green (0, 255,
// 0)), and returns the report data's "acquisition_thumbnails": {"measurement_photos", "shown", "size_px", "photos":
// [{"index", "file", "samples" (from `photos`), "outline" (false where the photo has no pose or the sample projects
// nowhere), "crop" [x0, y0, x1, y1], "step"} or {"index", "note"} where the photo could not be read]}, plus "note" when
// the mesh cannot be read (the photos are then shown without an outline).
nlohmann::json WriteAcquisitionThumbnails(const Session& session, const std::map<uint32_t, PhotoStats>& photos,
                                          const std::string& tmp_dir,
                                          const AcquisitionThumbnailOptions& options = AcquisitionThumbnailOptions());

}  // namespace ibrdf
