// A pbrt-v4 scene of one session photo rendered from the measured spatially varying model: the camera
// at the photo's pose, its light, and the scanned mesh with each face's material, a mix of the two
// groups of the largest weights (material_mesh.h) in steps of `amount_step`, each group its own
// exported pbrt-v4 material (reconstruction_stage.h's NAME.pbrt). Rendered by pbrt-v4 beside the photo
// it shows what a renderer makes of the measurement (tests/spatial/material_scene_pbrt_test.cc renders
// it with pbrt-v4 itself).
//
// pbrt-v4's mix picks one of two materials with a probability and cannot scale a material up, and every
// exported basis already gives its mix its full share (reconstruct/model_fit.h: amount = 1 - max
// diffuse). The weights' sum (a vertex's brightness against the groups, material_mesh.h's
// `weight_sum`) is carried by the light instead: its scale is the 99th percentile of the faces' sums (at
// least 1), and each face mixes its material with black to its own sum, in steps of `scale_step` of the
// light's; the brighter 1 % are held at the light's scale (counted).
//
// The film is the photo's size; the camera is the photo's pinhole (pbrt-v4's perspective camera with
// a screen window that puts the principal point where the photo has it, y flipped to pbrt's raster);
// the light's intensity is its scale (above), so that a pixel's value over (cos theta_i / r^2) of its
// surface point is the model's BRDF; one bounce (ibrdf measures direct reflection). Faces without weights on all three
// vertices are black diffuse (they still cast shadows). pbrt-v4's perspective camera has no lens
// distortion: the image is the undistorted pinhole's, photo pixel p rendered at (fx x + cx, fy y + cy)
// with (x, y) = Camera::CamPlaneFromImage(p). A photo without a pose is not written.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/brdf_model.h"
#include "core/session.h"
#include "spatial/material_mesh.h"
#include "spatial/material_weights.h"

namespace ibrdf {

struct PbrtSceneOptions {
  double amount_step = 0.1;    // the mixes' amounts are rounded to this
  double scale_step = 0.02;    // the faces' brightness (a fraction of the light's scale) is rounded to this
  double max_scale_percentile = 0.99;  // of the faces' weight sums: the light's scale
  int samples_per_pixel = 64;  // pbrt's mix picks one material per shading point: noise falls as 1/sqrt
  bool Check(std::string* why) const;
};

struct PbrtSceneResult {
  bool written = false;
  std::string not_written;  // why, when not written
  size_t photo = 0;         // the session photo rendered
  std::string file;         // the scene, relative to the output folder ("pbrt/photo-3.pbrt")
  std::string image;        // the EXR pbrt writes, relative to the scene's folder
  std::string mitsuba_file;         // the same scene for Mitsuba 3 ("mitsuba/photo-3.xml"), its shapes pbrt/'s parts
  std::string mitsuba_not_written;  // why not, when not (a group without its NAME.xml)
  std::string model_image;    // ibrdf's own render of the same model (RenderSceneModel), relative to the scene's folder
  uint64_t model_pixels = 0;  // and its rendered pixels
  // From RenderSceneModel: its samples' cells' weight sums, and the full model's brightness over its render's.
  double weight_sum_p05 = 0.0, weight_sum_median = 0.0, weight_sum_p95 = 0.0, full_model_ratio = 1.0;
  bool undistorted = false;  // the camera has distortion that the render leaves out (see above)
  int materials = 0;         // named materials: the groups, each mix used and each at a fraction of the light
  uint64_t faces = 0, faces_unmeasured = 0;
  double light_scale = 1.0;          // the light's intensity: the faces' weight sums' percentile, at least 1
  uint64_t faces_scale_clipped = 0;  // faces brighter than it, rendered at it

  // "pbrt/photo-3.pbrt: 133367 faces in 14 materials (61 % unmeasured, black); render: pbrt pbrt/photo-3.pbrt;
  // ibrdf's render of the model: photo-3-ibrdf.exr"
  std::string BriefReport() const;
};

// Writes out_dir/pbrt/photo-N.pbrt and its mesh parts (part-K.ply), and out_dir/mitsuba/photo-N.xml, the
// same scene for Mitsuba 3 (each group's NAME.xml beside its NAME.pbrt inlined; blendbsdf for the mixes).
// `basis_snippets[b]` is the pbrt-v4 material file of vertices.bases[b], relative to out_dir, defining
// `basis_names[b]`.
PbrtSceneResult WritePbrtScene(const Session& session, size_t photo, const VertexMaterials& vertices,
                               const std::vector<std::string>& basis_snippets,
                               const std::vector<std::string>& basis_names, const std::string& out_dir,
                               const PbrtSceneOptions& options);

// ibrdf's own render of the scene's photo from the measured model, to hold pbrt-v4's render against: at
// each of the photo's located samples in a fitted cell, the radiance a light of unit intensity gives,
// sum_b w_b f_b(wi, wo) cos(theta_i) / r^2 (a point light; a directional one without the 1 / r^2), with
// `fits` f, each group's GGX fit (the source of its pbrt-v4 material), and w the cell's two largest
// weights scaled to sum to the cell's sum of weights, at most `light_scale` (as the scene has them). Written
// at the sample's pixel in the undistorted pinhole's raster (pbrt's, see above; samples that fall into one
// pixel averaged) as a float RGBA EXR whose alpha is 1 where rendered and 0 elsewhere. The scene
// still differs from this: its weights are per face (its vertices' mean) and rounded to the amount step;
// each fit is a mix of a diffuse and a conductor (reconstruct/model_fit.h's RendererMaterials); and
// pbrt's mixes are stochastic (noise that falls with the samples per pixel).
struct SceneModelRender {
  bool written = false;
  std::string image;    // relative to the output folder ("pbrt/photo-3-ibrdf.exr")
  uint64_t pixels = 0;  // rendered
  // The rendered samples' cells' weight sums, and the model with the cells' full weights (every basis,
  // no cap) against the render's: sum of radiance over the samples, all channels.
  double weight_sum_p05 = 0.0, weight_sum_median = 0.0, weight_sum_p95 = 0.0;
  double full_model_ratio = 1.0;
};
SceneModelRender RenderSceneModel(const Session& session, size_t photo, const std::vector<LocatedSample>& samples,
                                  const MaterialWeightsResult& weights, const std::vector<const BrdfModel*>& fits,
                                  const Eigen::Vector3d& origin, double cell_m, double light_scale,
                                  const std::string& out_dir);

}  // namespace ibrdf
