// One photo predicted from the measured spatially varying model: each of its samples' BRDF value
// against the combination of the groups its cell was given (material_weights.h) at the sample's own
// directions, beside the one BRDF the object was reconstructed as and, for a synthetic session, the
// truth. With the photo held out of the grouping, reconstruction and projection, this is the held-out
// check of Lensch et al. 2003 (section 8: a photo not used, rendered from the model). The picture
// (photo-N.png) puts the photo, the photo as the model renders it (each sample pixel scaled by model /
// measured: the photo's own radiometry, the model's reflectance; exact for a linear response) and the
// ratio side by side, cropped about the samples. Held out means out of this stage: the uniformity
// check's groups of cells, which the groups start from, were formed with every photo.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/brdf_model.h"
#include "core/session.h"
#include "spatial/material_weights.h"

namespace ibrdf {

class MaterialMap;  // synth/material_map.h

struct PhotoPrediction {
  bool done = false;
  size_t photo = 0;
  bool held_out = false;     // the photo's samples took no part in the model
  uint64_t samples = 0;      // the photo's located samples
  uint64_t predicted = 0;    // of them, in a fitted cell with every basis valued in some channel
  // Per channel and pooled, the median |f / measured - 1| over the predicted samples of: the model, the
  // object's one BRDF (NaN without it), the truth (NaN without one: the samples' own noise).
  Eigen::Vector3d model_error = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d single_error = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d truth_error = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double model_error_all = std::numeric_limits<double>::quiet_NaN();
  double single_error_all = std::numeric_limits<double>::quiet_NaN();
  double truth_error_all = std::numeric_limits<double>::quiet_NaN();
  std::string image;  // the picture, relative to the output folder ("" when not drawn)

  // "photo 3 (held out): 5120 of 5210 samples predicted; median error 4.1 % (one BRDF 21.3 %, truth 1.2 %)"
  std::string BriefReport() const;
  nlohmann::json ToJson() const;
};

// Predicts `samples` (one photo's, located; any order) from `weights` over `bases` (the cells' keys as
// UniformityCellKey gives them for `origin` and `cell_m`), and from `single` and `truth` where given
// (nullptr: none). Draws the picture into out_dir/photo-N.png when the photo can be read at the camera's
// size (else image stays empty).
PhotoPrediction PredictPhoto(const Session& session, size_t photo, bool held_out,
                             const std::vector<LocatedSample>& samples, const MaterialWeightsResult& weights,
                             const std::vector<const BrdfModel*>& bases, const Eigen::Vector3d& origin,
                             double cell_m, const BrdfModel* single, const MaterialMap* truth,
                             const std::string& out_dir);

}  // namespace ibrdf
