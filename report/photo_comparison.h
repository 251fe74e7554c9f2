// The measured photo beside renderings of the actual sample from the photo's own camera: at every pixel
// that gave a sample, the derenderer found the surface point, its normal, wi and wo (sphere, cylinder
// or the scanned mesh, shadows included) and divided the pixel's radiance by E cos(theta_i) to get f.
// A model's rendering of that pixel is f_model(wi, wo) E cos(theta_i) = f_model(wi, wo) * pixel /
// f_sample, per channel: the same geometry, camera and light, the model's BRDF. The signed difference
// (render - photo) / photo is then f_model / f_sample - 1 at each sample's pixel.
#pragma once

#include <string>
#include <vector>

#include "core/image_io.h"
#include "core/sample_file.h"
#include "report/sphere_render.h"

namespace ibrdf {

// A pixel box, inclusive.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  int width() const { return x1 - x0 + 1; }
  int height() const { return y1 - y0 + 1; }
};

// One model's rendering of the photo's crop and its signed difference from the photo.
struct PhotoRender {
  std::string model;  // "reconstruction", "lafortune", "ggx", "truth"
  Image linear;       // RGB, the photo's units; 0 where no sample fell, NaN where the model has no value
  Image difference;   // one channel: (render - photo) / photo in luminance; NaN where either is missing
  double median_abs_difference = 0.0;  // over the pixels that have one
};

// The derender stride of the samples: the smallest positive step between sample columns in one row
// (1 when every pixel gave a sample; 1 with fewer than two samples).
int SampleStride(const std::vector<const BrdfSample*>& samples);

// Renders `model` at the pixels of `samples` (one photo's) inside `box` of `photo` (linear RGB, full
// resolution); each sample fills its stride x stride block (SampleStride), so the render has the crop's
// full size.
PhotoRender RenderPhotoPixels(const Image& photo, const PixelBox& box, const std::vector<const BrdfSample*>& samples,
                              const std::string& model, const BrdfEvalFunction& eval);

// The same with the model's values given per sample (values[i] for samples[i], RGB; a negative or NaN
// component: no value), e.g. a regression evaluated at all of a photo's samples at once.
PhotoRender RenderPhotoPixels(const Image& photo, const PixelBox& box, const std::vector<const BrdfSample*>& samples,
                              const std::string& model, const std::vector<Eigen::Vector3d>& values);

// The crop of `photo` to `box` (RGB; a grey photo's one channel copied to three).
Image CropPhoto(const Image& photo, const PixelBox& box);

}  // namespace ibrdf
