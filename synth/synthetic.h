// Synthetic measurement sessions with known truth (COLMAP's scene/synthetic.h in spirit): a forward
// renderer for the analytic sphere and cylinder under one point light, photographed from camera
// positions on an arc from beside the light to opposite it (the paper's Figures 3 and 4), with the
// camera effects of a real sensor that can each be switched off. Irregular true shapes (a squash, a
// clay pot, a dented sphere: synth/synthetic_shapes.h) are rendered exactly, with shadow rays, on
// the target platform, and written as a mesh sample measured by a simulated range scanner (docs/synth.md).
// The options, split by concern, are in synth/synth_options.h; the marker layouts in
// synth/synthetic_targets.h; the sensor, brackets and white reference in synth/synthetic_radiometry.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/session.h"
#include "synth/material_map.h"
#include "synth/synth_options.h"
#include "synth/synthetic_shapes.h"

namespace ibrdf {

// The true shape of an irregular-shape session (centred at scene.origin); null for kNone.
std::unique_ptr<ImplicitSample> MakeTrueShape(const SynthSceneOptions& scene);

// The scanner's frame of an irregular-shape session (see SynthScanOptions::offset_m).
Rigid3d ScanFromWorld(const SynthScanOptions& scan);

// Renders the ideal (noise-free, unclipped) radiance image of one photo; radiance is 0 off the sample.
// `hit_mask` (optional) gets 1 where the pixel centre sees the sample.
Image RenderRadiance(const Session& session, size_t photo_index, const BrdfModel& material, int supersample,
                     std::vector<uint8_t>* hit_mask);
// The same for a given true shape; with `shadow_rays` a hit is lit only where the segment to the light
// is free of the shape (non-convex truths cast shadows on themselves).
Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const BrdfModel& material, int supersample, std::vector<uint8_t>* hit_mask);
// The same with a spatially varying material: each hit's BRDF is map.Eval at its world point.
Image RenderRadiance(const Session& session, size_t photo_index, const AnalyticSample& truth, bool shadow_rays,
                     const MaterialMap& map, int supersample, std::vector<uint8_t>* hit_mask);

// What WriteSyntheticSession wrote; reads as failure until it ran.
struct SynthSummary {
  bool success = false;
  int photos = 0;
  uint64_t saturated_pixels = 0;  // pixels with a clipped channel
  uint64_t shadowed_pixels = 0;   // sample pixels facing the light but in the shape's own shadow
  int scan_views = 0;             // irregular shapes: range grids written
  uint64_t scan_points = 0;       // their points
  // A tabulated material (a MERL table) and its cells without data (SynthOptions::no_data): the
  // table's count of such cells, the measurement photos' pixels with a ray that looked one up, and
  // (kSkip) the photos whose mask (masks/NAME.png) leaves those pixels out of the samples.
  bool tabulated = false;
  uint64_t table_cells_without_data = 0;
  uint64_t no_data_pixels = 0;
  int masked_photos = 0;
  SynthNoData no_data = SynthNoData::kSkip;
  double total_s = 0.0;
  std::string BriefReport() const;  // one line: photos, time, clipped pixels (and shadows and scans)
  // One line on the pixels that looked up cells without data and what became of them; empty when none.
  std::string NoDataReport() const;
};

// Writes a complete session folder: session.json, photos/, and truth.json with the material and the
// generator options. The folder appears only when complete. Throws Error for invalid options, and
// (options.no_data kError) for a tabulated material whose cells without data a sample pixel looks up.
// With kSkip such pixels are left out through a mask per photo (masks/, session.json's photo "mask").
SynthSummary WriteSyntheticSession(const SynthOptions& options, const BrdfModel& material,
                                   const std::string& material_name, const std::string& out_dir, bool overwrite);
// The same with a spatially varying material (`map_name`: the map's file): every hit's BRDF is
// map.Eval at its world point, and truth.json holds "material_map" (MaterialMap::ToJson, the
// materials embedded) in place of "material", since no single material is the truth. Throws Error
// naming `map_name` for a basis material that is a MERL table with cells without data (a map has no
// per-material mask of them).
SynthSummary WriteSyntheticSession(const SynthOptions& options, const MaterialMap& map, const std::string& map_name,
                                   const std::string& out_dir, bool overwrite);

}  // namespace ibrdf
