#include "report/photo_comparison.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <map>

#include "core/error.h"
#include "core/statistics.h"

namespace ibrdf {

int SampleStride(const std::vector<const BrdfSample*>& samples) {
  std::map<uint32_t, std::vector<uint32_t>> rows;
  for (const BrdfSample* s : samples) rows[s->pixel[1]].push_back(s->pixel[0]);
  int stride = INT_MAX;
  for (auto& [row, columns] : rows) {
    std::sort(columns.begin(), columns.end());
    for (size_t i = 1; i < columns.size(); ++i) {
      if (columns[i] > columns[i - 1]) stride = std::min<int>(stride, int(columns[i] - columns[i - 1]));
    }
  }
  return stride == INT_MAX ? 1 : stride;
}

Image CropPhoto(const Image& photo, const PixelBox& box) {
  Image crop(box.width(), box.height(), 3);
  for (int y = box.y0; y <= box.y1; ++y) {
    for (int x = box.x0; x <= box.x1; ++x) {
      for (int c = 0; c < 3; ++c) crop.at(x - box.x0, y - box.y0, c) = photo.at(x, y, std::min(c, photo.channels - 1));
    }
  }
  return crop;
}

PhotoRender RenderPhotoPixels(const Image& photo, const PixelBox& box, const std::vector<const BrdfSample*>& samples,
                              const std::string& model, const BrdfEvalFunction& eval) {
  std::vector<Eigen::Vector3d> values(samples.size(), Eigen::Vector3d::Constant(NAN));
  for (size_t i = 0; i < samples.size(); ++i) {
    const BrdfSample* s = samples[i];
    const int px = int(s->pixel[0]), py = int(s->pixel[1]);
    if (px < box.x0 || px > box.x1 || py < box.y0 || py > box.y1) continue;
    values[i] = eval(Eigen::Vector3d(s->wi[0], s->wi[1], s->wi[2]).normalized(),
                     Eigen::Vector3d(s->wo[0], s->wo[1], s->wo[2]).normalized());
  }
  return RenderPhotoPixels(photo, box, samples, model, values);
}

PhotoRender RenderPhotoPixels(const Image& photo, const PixelBox& box, const std::vector<const BrdfSample*>& samples,
                              const std::string& model, const std::vector<Eigen::Vector3d>& values) {
  IBRDF_CHECK(values.size() == samples.size()) << values.size() << " values for " << samples.size() << " samples";
  PhotoRender render;
  render.model = model;
  render.linear = Image(box.width(), box.height(), 3);
  render.difference = Image(box.width(), box.height(), 1);
  std::fill(render.difference.pixels.begin(), render.difference.pixels.end(), NAN);
  const int stride = SampleStride(samples);
  const int before = stride / 2;
  std::vector<double> differences;
  for (size_t i = 0; i < samples.size(); ++i) {
    const BrdfSample* s = samples[i];
    const int px = int(s->pixel[0]), py = int(s->pixel[1]);
    if (px < box.x0 || px > box.x1 || py < box.y0 || py > box.y1) continue;
    const Eigen::Vector3d& f = values[i];
    // The sample's own pixel: E cos(theta_i) per channel, as the derenderer divided by it.
    double rendered[3];
    for (int c = 0; c < 3; ++c) {
      const double measured = photo.at(px, py, std::min(c, photo.channels - 1));
      const double irradiance = s->brdf[c] > 0.0f ? measured / s->brdf[c] : NAN;
      rendered[c] = f[c] >= 0.0 ? f[c] * irradiance : NAN;
    }
    // The difference over the channels the sample measured (its `valid` flags): a clipped channel's
    // photo value is the clip level, one under the noise floor is noise, so neither is compared; the
    // luminance weights of the measured channels only. NaN when none is measured or a value is missing.
    const double weights[3] = {0.2126, 0.7152, 0.0722};
    double render_sum = 0.0, photo_sum = 0.0;
    bool ok = false;
    for (int c = 0; c < 3; ++c) {
      if (!s->Valid(c)) continue;
      ok = true;
      render_sum += weights[c] * rendered[c];
      photo_sum += weights[c] * photo.at(px, py, std::min(c, photo.channels - 1));
    }
    const double d = ok && photo_sum > 0.0 && std::isfinite(render_sum) ? render_sum / photo_sum - 1.0 : NAN;
    if (std::isfinite(d)) differences.push_back(std::abs(d));
    // Its stride x stride block shows it.
    for (int y = std::max(box.y0, py - before); y <= std::min(box.y1, py - before + stride - 1); ++y) {
      for (int x = std::max(box.x0, px - before); x <= std::min(box.x1, px - before + stride - 1); ++x) {
        for (int c = 0; c < 3; ++c) render.linear.at(x - box.x0, y - box.y0, c) = float(rendered[c]);
        render.difference.at(x - box.x0, y - box.y0, 0) = float(d);
      }
    }
  }
  render.median_abs_difference = differences.empty() ? NAN : Percentile(differences, 0.5);
  return render;
}

}  // namespace ibrdf
