// Next-shot planning: which camera positions, within a reachable range, fill the largest unmeasured
// regions of the BRDF domain left by a session's photos. Candidates on a shell around the sample (each
// looking at its centre, under the session's light) are scored by the MERL cells they would bring within
// the reconstruction's "measured" distance (DomainRules::measured_nearest kernel radii of a predicted
// sample, in the regression's scaled (u, v, w) with its folds, reconstruct/local_regression.h) and
// within the samples' theta_d range (beyond it no cell is measured), weighted towards the specular
// region; the best is taken and the step repeated (greedy set cover). The coverage before and after is
// then the reconstruction's full classification (coverage/coverage.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "coverage/coverage.h"

namespace ibrdf {

struct ShotPlanOptions {
  int suggestions = 4;  // photos to suggest (greedy steps)
  // The reachable range: camera positions on a shell about the sample's centre at this distance
  // (metres; 0: the mean distance of the session's cameras), at elevations (degrees above the world's
  // xy plane through the centre; world +z is up) and azimuths (degrees about +z from +x) in these ranges,
  // on a grid of these steps (at least 1 degree).
  double distance_m = 0.0;
  double min_elevation_deg = 10.0, max_elevation_deg = 80.0, elevation_step_deg = 10.0;
  double min_azimuth_deg = -180.0, max_azimuth_deg = 180.0, azimuth_step_deg = 15.0;
  // Candidates whose direction from the centre lies within this angle of the light's are left out: the
  // camera would stand in front of the light (or the light in the photo).
  double min_light_separation_deg = 8.0;
  // Cells of theta_h below specular_theta_h_deg count specular_weight times in a candidate's gain: the
  // specular peak is where an unmeasured cell costs the most reconstruction error.
  double specular_theta_h_deg = 20.0;
  double specular_weight = 4.0;
  // Predicted samples per candidate view for its score (the cells within the measured distance need
  // fewer than the full classification); the chosen ones are traced again at coverage.samples_per_view.
  int candidate_samples_per_view = 3000;
  CoverageOptions coverage;
  bool Check(std::string* why) const;
};

// One suggested photo.
struct ShotSuggestion {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // camera centre, world frame, metres
  Eigen::Vector3d look_at = Eigen::Vector3d::Zero();   // the sample's centre
  double azimuth_deg = 0.0, elevation_deg = 0.0, distance_m = 0.0;
  Rigid3d camera_from_world;    // looking at look_at, image up towards world +z
  uint64_t cells_gained = 0;    // MERL cells newly within the measured distance (both bilateral halves)
  double weighted_gain = 0.0;   // the greedy score (specular cells weighted)
};

// What the planning found; reads as failure until it ran.
struct ShotPlan {
  bool success = false;
  uint64_t candidates = 0;
  double distance_m = 0.0;
  CoverageResult before, after;  // the reconstruction's classification without and with the suggestions
  std::vector<ShotSuggestion> suggestions;
  double seconds = 0.0;
  std::string BriefReport() const;
};
nlohmann::json ToJson(const ShotPlan& plan);

// Plans options.suggestions photos added to `views` (the light of the first view lights every
// candidate). Throws Error for no views, a mesh sample or bad options.
ShotPlan PlanShots(const Camera& camera, const SampleSpec& sample, const std::vector<CoverageView>& views,
                   const ShotPlanOptions& options);

// A picture of the plan: the (theta_d across, theta_h down) maps of the fraction of phi_d cells
// measured, before (left) and after (right; cells the suggestions add in orange), 4 pixels a cell, as
// a PNG at `path`.
void WriteCoveragePicture(const ShotPlan& plan, const std::string& path);

// `ibrdf capture check`'s outputs for `session`, planned as `plan` from its posed views (`missing`: the
// measurement photos left out and why, SessionViews): DIR/capture-check.json (every measurement
// photo's pose and light, the plan, what is not modelled) and DIR/coverage.png (WriteCoveragePicture),
// as one folder that appears complete (replacing `out_dir` only with `overwrite`).
void WriteCaptureCheck(const Session& session, const ShotPlan& plan, const std::vector<std::string>& missing,
                       const std::string& out_dir, bool overwrite);

}  // namespace ibrdf
