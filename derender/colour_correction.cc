#include "derender/colour_correction.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/colour.h"
#include "core/error.h"

namespace ibrdf {
namespace {

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

std::string Percent(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f %%", 100.0 * value);
  return text;
}

}  // namespace

Eigen::Matrix3d SampleColourMatrix(const ColourChartSpec& chart, const Eigen::Vector3d& light_intensity) {
  IBRDF_CHECK(chart.matrix.has_value());
  const Eigen::Matrix3d srgb_from_camera = LinearSrgbFromSpace(chart.space, *chart.matrix);
  const Eigen::Vector3d light_srgb = srgb_from_camera * light_intensity;
  const Eigen::Matrix3d corrected =
      light_srgb.cwiseInverse().asDiagonal() * srgb_from_camera * light_intensity.asDiagonal();
  return SpaceFromLinearSrgb(chart.space, corrected);
}

std::vector<Eigen::Matrix3d> SampleColourMatrices(const Session& session) {
  if (!session.colour_chart) return {};
  const ColourChartSpec& chart = *session.colour_chart;
  if (!chart.matrix) {
    ThrowError(session.manifest_path + ": /colour_chart",
               "has no fitted matrix: run `ibrdf colour` on the session first (it writes the matrix)");
  }
  std::vector<Eigen::Matrix3d> matrices;
  for (size_t k = 0; k < session.lights.size(); ++k) {
    const Eigen::Vector3d& intensity = session.lights[k].intensity;
    const Eigen::Vector3d light_srgb = LinearSrgbFromSpace(chart.space, *chart.matrix) * intensity;
    if (!(light_srgb.minCoeff() > 0.0)) {
      ThrowError(session.manifest_path + ": /colour_chart/matrix",
                 "maps the light's intensity to a colour with a channel <= 0; the chart's matrix does not fit "
                 "this session's camera");
    }
    matrices.push_back(SampleColourMatrix(chart, intensity));
  }
  return matrices;
}

void ApplyColourMatrices(const Session& session, const std::vector<Eigen::Matrix3d>& matrices,
                         std::vector<BrdfSample>* samples, ColourCorrectionCounts* counts) {
  if (matrices.empty()) return;
  ColourCorrectionCounts& tally = *counts;
  std::vector<Eigen::Matrix3f> single(matrices.size()), squared(matrices.size());
  for (size_t k = 0; k < matrices.size(); ++k) {
    single[k] = matrices[k].cast<float>();
    squared[k] = single[k].cwiseAbs2();
  }
  for (BrdfSample& sample : *samples) {
    const size_t light = session.photos.at(sample.image).light;
    const Eigen::Vector3f brdf = single[light] * Eigen::Map<const Eigen::Vector3f>(sample.brdf);
    const Eigen::Vector3f variance =
        squared[light] * Eigen::Map<const Eigen::Vector3f>(sample.sigma).cwiseAbs2();
    // A corrected channel mixes the camera's channels: it is measured only when every channel it takes
    // from is (a clipped or below-floor input would leak into it); otherwise valid 0 and sigma 0.
    uint8_t valid[3];
    for (int c = 0; c < 3; ++c) {
      valid[c] = 1;
      for (int j = 0; j < 3; ++j) {
        if (single[light](c, j) != 0.0f && sample.valid[j] == 0) valid[c] = 0;
      }
    }
    for (int c = 0; c < 3; ++c) {
      // A matrix with negative terms takes a noisy dark channel below 0: that value is no measurement
      // of a BRDF (which is never negative), so the channel is unmeasured, like one below the floor;
      // the sample keeps its other channels.
      const bool usable = std::isfinite(brdf[c]) && brdf[c] >= 0.0f;
      if (valid[c] && !usable) {
        valid[c] = 0;
        ++tally.negative[c];
      }
      sample.brdf[c] = usable ? brdf[c] : 0.0f;
      sample.sigma[c] = valid[c] ? std::sqrt(variance[c]) : 0.0f;
      sample.valid[c] = valid[c];
    }
  }
  // Samples left with no measured channel carry nothing: removed and counted.
  const size_t before = samples->size();
  const auto unmeasured = [](const BrdfSample& s) { return s.valid[0] == 0 && s.valid[1] == 0 && s.valid[2] == 0; };
  samples->erase(std::remove_if(samples->begin(), samples->end(), unmeasured), samples->end());
  tally.dropped += before - samples->size();
}

std::vector<Eigen::Matrix3d> ApplyColourCorrection(const Session& session, std::vector<BrdfSample>* samples,
                                                   ColourCorrectionCounts* counts) {
  ColourCorrectionCounts tally;
  if (counts != nullptr) *counts = tally;
  const std::vector<Eigen::Matrix3d> matrices = SampleColourMatrices(session);
  ApplyColourMatrices(session, matrices, samples, &tally);
  if (counts != nullptr) *counts = tally;
  return matrices;
}

nlohmann::json ColourSidecar(const Session& session, const std::vector<Eigen::Matrix3d>& applied) {
  if (!session.colour_chart) return nullptr;
  const ColourChartSpec& chart = *session.colour_chart;
  nlohmann::json json = {
      {"chart", chart.chart}, {"space", ColourSpaceName(chart.space)}, {"reference", ColorCheckerReferenceSource()}};
  if (chart.matrix) json["space_from_camera"] = MatrixJson(*chart.matrix);
  nlohmann::json patches = nlohmann::json::array();
  double sum_squares = 0.0, worst = 0.0;
  int used = 0;
  for (const ColourPatchFit& fit : chart.patches) {
    if (fit.excluded.empty()) {
      patches.push_back({{"name", fit.name}, {"residual", fit.residual}});
      sum_squares += fit.residual * fit.residual;
      worst = std::max(worst, fit.residual);
      ++used;
    } else {
      patches.push_back({{"name", fit.name}, {"excluded", fit.excluded}});
    }
  }
  json["patches"] = patches;
  if (used > 0) {
    json["rms_residual"] = std::sqrt(sum_squares / used);
    json["max_residual"] = worst;
  }
  nlohmann::json per_light = nlohmann::json::array();
  for (size_t k = 0; k < applied.size(); ++k) {
    per_light.push_back({{"light", session.lights[k].id}, {"space_from_camera_brdf", MatrixJson(applied[k])}});
  }
  json["applied"] = per_light;
  json["applied_meaning"] =
      "brdf_out = space_from_camera_brdf * brdf_camera per sample, by its photo's light: the chart's matrix with "
      "the light's colour balanced to white (derender/colour_correction.h, SampleColourMatrix)";
  return json;
}

std::string ColourCorrectionReport(const Session& session, const std::vector<Eigen::Matrix3d>& applied) {
  if (!session.colour_chart || !session.colour_chart->matrix) return "colour: none (camera RGB)";
  const ColourChartSpec& chart = *session.colour_chart;
  auto matrix_text = [](const Eigen::Matrix3d& m) {
    char text[160];
    std::snprintf(text, sizeof(text), "[[%.5g, %.5g, %.5g], [%.5g, %.5g, %.5g], [%.5g, %.5g, %.5g]]", m(0, 0), m(0, 1),
                  m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2));
    return std::string(text);
  };
  std::string out = std::string("colour: samples corrected to ") + ColourSpaceName(chart.space) +
                    "; the chart's space_from_camera " + matrix_text(*chart.matrix) + "\n  patch residuals:";
  for (size_t k = 0; k < chart.patches.size(); ++k) {
    const ColourPatchFit& fit = chart.patches[k];
    out += (k % 4 == 0 ? "\n    " : "; ") + fit.name + " " +
           (fit.excluded.empty() ? Percent(fit.residual) : "left out (" + fit.excluded + ")");
  }
  for (size_t k = 0; k < applied.size(); ++k) {
    out += "\n  applied to the samples under light " +
           (session.lights[k].id.empty() ? std::to_string(k) : session.lights[k].id) + ": " + matrix_text(applied[k]);
  }
  return out;
}

std::string ColourSpaceDescription(const Session& session) {
  if (session.colour_chart && session.colour_chart->matrix) {
    return std::string(ColourSpaceLabel(session.colour_chart->space)) +
           ": camera RGB through the colour chart's matrix (see \"colour\")";
  }
  return "camera RGB, linear (the session's response inverted, black level subtracted)";
}

}  // namespace ibrdf
