// A pbrt-v4 scene of one session photo rendered from the measured spatially varying model: the camera
// at the photo's pose, its light, and the scanned mesh with each face's material, a mix of the two
// groups of the largest weights (material_mesh.h) in steps of `amount_step`, each group its own
// exported pbrt-v4 material (reconstruction_stage.h's NAME.pbrt). Rendered by pbrt-v4 beside the photo
// it shows what a renderer makes of the measurement (tests/spatial/material_scene_pbrt_test.cc renders
// it with pbrt-v4 itself).
//
// The film is the photo's size; the camera is the photo's pinhole (pbrt-v4's perspective camera with
// a screen window that puts the principal point where the photo has it, y flipped to pbrt's raster);
// the light has unit intensity, so that a pixel's value over (cos theta_i / r^2) of its surface point is
// the rendered BRDF; one bounce (ibrdf measures direct reflection). Faces without weights on all three
// vertices are black diffuse (they still cast shadows). pbrt-v4's perspective camera has no lens
// distortion: the image is the undistorted pinhole's, photo pixel p rendered at (fx x + cx, fy y + cy)
// with (x, y) = Camera::CamPlaneFromImage(p). A photo without a pose is not written.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/session.h"
#include "spatial/material_mesh.h"

namespace ibrdf {

struct PbrtSceneOptions {
  double amount_step = 0.1;    // the mixes' amounts are rounded to this
  int samples_per_pixel = 64;  // pbrt's mix picks one material per shading point: noise falls as 1/sqrt
  bool Check(std::string* why) const;
};

struct PbrtSceneResult {
  bool written = false;
  std::string not_written;  // why, when not written
  size_t photo = 0;         // the session photo rendered
  std::string file;         // the scene, relative to the output folder ("pbrt/photo-3.pbrt")
  std::string image;        // the EXR pbrt writes, relative to the scene's folder
  bool undistorted = false;  // the camera has distortion that the render leaves out (see above)
  int materials = 0;        // named materials: the groups, and each mix used
  uint64_t faces = 0, faces_unmeasured = 0;

  // "pbrt/photo-3.pbrt: 133367 faces in 14 materials (61 % unmeasured, black); render: pbrt pbrt/photo-3.pbrt"
  std::string BriefReport() const;
};

// Writes out_dir/pbrt/photo-N.pbrt and its mesh parts (part-K.ply). `basis_snippets[b]` is the pbrt-v4
// material file of vertices.bases[b], relative to out_dir, defining `basis_names[b]`.
PbrtSceneResult WritePbrtScene(const Session& session, size_t photo, const VertexMaterials& vertices,
                               const std::vector<std::string>& basis_snippets,
                               const std::vector<std::string>& basis_names, const std::string& out_dir,
                               const PbrtSceneOptions& options);

}  // namespace ibrdf
