// Colour in synthetic sessions (docs/synth.md, "Colour"): the camera's colour matrix (camera RGB from
// the renderer's linear sRGB) and a photo of a ColorChecker Classic whose patches have the chart's
// published linear-sRGB albedos (core/colour.h), so that `ibrdf colour` can be checked end to end
// against a known truth. Options: SynthColourOptions (synth/synth_options.h).
#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "core/image_io.h"
#include "core/session.h"
#include "synth/synth_options.h"

namespace ibrdf {

// Radiance (or signal) in linear sRGB to camera RGB in place: every pixel's RGB times `camera_matrix`
// (nothing for the identity or a grey image).
void ApplyCameraMatrix(const Eigen::Matrix3d& camera_matrix, Image* image);

// Hook before the session is saved, in the folder being written (`directory`), after the white
// reference: writes the chart photo (calibration/colour-chart.png or .exr) and the colour_chart block
// when options.colour.chart, then states every light's intensity in camera RGB (camera_matrix times
// the rendered one). Returns what truth.json records (the matrix, the chart's albedos and where its
// corner patches are); null when there is no colour to record. Throws Error when the matrix makes
// a light's camera-RGB intensity non-positive.
nlohmann::json WriteSynthColour(const SynthOptions& options, const std::string& directory, Session* session);

}  // namespace ibrdf
