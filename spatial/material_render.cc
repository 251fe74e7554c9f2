#include "spatial/material_render.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "core/file_util.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "core/png_writer.h"
#include "core/statistics.h"
#include "spatial/uniformity.h"
#include "synth/material_map.h"

namespace ibrdf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json Triple(const Eigen::Vector3d& v) {
  nlohmann::json out = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) out.push_back(std::isfinite(v[k]) ? nlohmann::json(v[k]) : nlohmann::json(nullptr));
  return out;
}

nlohmann::json Scalar(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string Percent(double v) { return std::isfinite(v) ? Fixed(100.0 * v, 1) + " %" : "n/a"; }

// Per channel and pooled medians of the errors collected per channel.
void Medians(const std::vector<double> (&errors)[3], Eigen::Vector3d* per_channel, double* all) {
  std::vector<double> pooled;
  for (int k = 0; k < 3; ++k) {
    if (!errors[k].empty()) (*per_channel)[k] = Median(errors[k]);
    pooled.insert(pooled.end(), errors[k].begin(), errors[k].end());
  }
  if (!pooled.empty()) *all = Median(pooled);
}

}  // namespace

std::string PhotoPrediction::BriefReport() const {
  if (!done) return "no photo predicted";
  return "photo " + std::to_string(photo) + (held_out ? " (held out)" : " (in the measurement)") + ": " +
         std::to_string(predicted) + " of " + std::to_string(samples) + " samples predicted; median |model / measured - 1| " +
         Percent(model_error_all) + " (the one BRDF " + Percent(single_error_all) + ", the truth " +
         Percent(truth_error_all) + ")";
}

nlohmann::json PhotoPrediction::ToJson() const {
  return {{"photo", photo},
          {"held_out", held_out},
          {"samples", samples},
          {"predicted", predicted},
          {"model_median_abs_rel_error", Triple(model_error)},
          {"model_median_abs_rel_error_all", Scalar(model_error_all)},
          {"single_brdf_median_abs_rel_error", Triple(single_error)},
          {"single_brdf_median_abs_rel_error_all", Scalar(single_error_all)},
          {"truth_median_abs_rel_error", Triple(truth_error)},
          {"truth_median_abs_rel_error_all", Scalar(truth_error_all)},
          {"image", image.empty() ? nlohmann::json(nullptr) : nlohmann::json(image)}};
}

PhotoPrediction PredictPhoto(const Session& session, size_t photo, bool held_out,
                             const std::vector<LocatedSample>& samples, const MaterialWeightsResult& weights,
                             const std::vector<const BrdfModel*>& bases, const Eigen::Vector3d& origin,
                             double cell_m, const BrdfModel* single, const MaterialMap* truth,
                             const std::string& out_dir) {
  PhotoPrediction result;
  result.done = true;
  result.photo = photo;
  result.held_out = held_out;
  const std::unordered_map<uint64_t, size_t> cell_of_key = FittedCellsByKey(weights);
  const Camera& camera = session.camera;
  // Per predicted sample: its pixel, and model / measured per channel (NaN where not predicted).
  struct Drawn {
    uint32_t x = 0, y = 0;
    Eigen::Vector3d ratio = Eigen::Vector3d::Constant(kNaN);
  };
  std::vector<Drawn> drawn;
  std::vector<double> model_errors[3], single_errors[3], truth_errors[3];
  for (const LocatedSample& located : samples) {
    if (located.sample.image != photo) continue;
    ++result.samples;
    const auto it = cell_of_key.find(UniformityCellKey(located.point.cast<double>(), origin, cell_m));
    if (it == cell_of_key.end()) continue;
    const CellWeights& cell = weights.cells[it->second];
    const BrdfSample& s = located.sample;
    const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
    Eigen::Vector3d model = Eigen::Vector3d::Zero();
    Eigen::Vector3i valued = Eigen::Vector3i::Ones();
    for (size_t b = 0; b < bases.size(); ++b) {
      const Eigen::Vector3d f = bases[b]->Eval(wi, wo);
      for (int k = 0; k < 3; ++k) {
        if (!(f[k] >= 0.0)) valued[k] = 0;
        model[k] += cell.weights[Eigen::Index(b)] * f[k];
      }
    }
    const Eigen::Vector3d f_single = single ? single->Eval(wi, wo) : Eigen::Vector3d::Constant(kNaN);
    const Eigen::Vector3d f_truth = truth ? truth->Eval(located.point.cast<double>(), wi, wo) : Eigen::Vector3d::Constant(kNaN);
    Drawn d;
    d.x = s.pixel[0];
    d.y = s.pixel[1];
    bool any = false;
    for (int k = 0; k < 3; ++k) {
      if (!s.Valid(k) || !(s.brdf[k] > 0.0f) || !valued[k]) continue;
      any = true;
      const double measured = s.brdf[k];
      d.ratio[k] = model[k] / measured;
      model_errors[k].push_back(std::abs(model[k] / measured - 1.0));
      if (std::isfinite(f_single[k]) && f_single[k] > 0.0) single_errors[k].push_back(std::abs(f_single[k] / measured - 1.0));
      if (std::isfinite(f_truth[k])) truth_errors[k].push_back(std::abs(f_truth[k] / measured - 1.0));
    }
    if (!any) continue;
    ++result.predicted;
    drawn.push_back(d);
  }
  Medians(model_errors, &result.model_error, &result.model_error_all);
  Medians(single_errors, &result.single_error, &result.single_error_all);
  Medians(truth_errors, &result.truth_error, &result.truth_error_all);

  // The picture: photo | the photo as the model renders it | model / measured.
  if (photo >= session.photos.size()) return result;
  const Image image = ReadImage(ResolvePath(session.directory, session.photos[photo].file));
  if (image.width != camera.width || image.height != camera.height || image.channels < 3) return result;
  std::vector<float> luminance;
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i) {
    const float* p = &image.pixels[i * size_t(image.channels)];
    luminance.push_back(0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]);
  }
  const float top = std::max(PercentileInPlace(&luminance, 0.99), 1e-6f);
  // Each panel is the samples' bounding box with a margin of a quarter of its size, within the photo.
  int x0 = image.width, y0 = image.height, x1 = 0, y1 = 0;
  for (const Drawn& d : drawn) {
    if (d.x >= uint32_t(image.width) || d.y >= uint32_t(image.height)) continue;
    x0 = std::min(x0, int(d.x));
    y0 = std::min(y0, int(d.y));
    x1 = std::max(x1, int(d.x) + 1);
    y1 = std::max(y1, int(d.y) + 1);
  }
  if (x1 <= x0 || y1 <= y0) return result;
  const int margin = std::max(x1 - x0, y1 - y0) / 4;
  x0 = std::max(0, x0 - margin);
  y0 = std::max(0, y0 - margin);
  x1 = std::min(image.width, x1 + margin);
  y1 = std::min(image.height, y1 + margin);
  const int w = x1 - x0, h = y1 - y0;
  Image picture(3 * w, h, 3);
  const auto display = [top](double v) { return float(std::sqrt(std::clamp(v / top, 0.0, 1.0))); };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = image.at(x0 + x, y0 + y, c);
        picture.at(x, y, c) = display(v);
        picture.at(w + x, y, c) = 0.3f * display(v);  // not predicted: the photo, dimmed
        picture.at(2 * w + x, y, c) = 0.3f * display(v);
      }
    }
  }
  for (const Drawn& d : drawn) {
    if (int(d.x) < x0 || int(d.x) >= x1 || int(d.y) < y0 || int(d.y) >= y1) continue;
    const int x = int(d.x) - x0, y = int(d.y) - y0;
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(d.ratio[c])) {
        picture.at(w + x, y, c) = display(image.at(int(d.x), int(d.y), c) * d.ratio[c]);
        const double l = std::log(std::max(d.ratio[c], 1e-12)) / std::log(1.5);
        if (std::abs(l) > std::abs(worst)) worst = l;
      }
    }
    // Red where the model is brighter than the photo, blue where darker, white where equal; full at 1.5x.
    const float t = float(std::clamp(worst, -1.0, 1.0));
    const float colour[3] = {t < 0 ? 1.0f + t : 1.0f, 1.0f - std::abs(t), t > 0 ? 1.0f - t : 1.0f};
    for (int c = 0; c < 3; ++c) picture.at(2 * w + x, y, c) = colour[c];
  }
  result.image = "photo-" + std::to_string(photo) + ".png";
  WritePlainPng((std::filesystem::path(out_dir) / result.image).string(), picture, PixelFormat::kUint8,
                PngEncoding::kAsOpenImageIo);
  return result;
}

}  // namespace ibrdf
