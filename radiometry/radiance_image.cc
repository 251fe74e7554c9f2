#include "radiometry/radiance_image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/file_util.h"
#include "core/huge_pages.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "radiometry/linear_image.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// Poses of one bracket may differ by this much (align poses each photo on its own).
constexpr double kBracketMaxTranslation = 1e-3;  // metres
constexpr double kBracketMaxRotation = 1e-3;     // radians

// Response lookup table: nodes over [0, 1] file values, used above kTableStart (below it, where a
// power curve bends hardest relative to its value, the response itself is evaluated).
constexpr int kTableIntervals = 8192;
constexpr double kTableStart = 1.0 / 64.0;

bool SamePose(const Rigid3d& a, const Rigid3d& b) {
  return a.rotation.coeffs() == b.rotation.coeffs() && a.translation == b.translation;
}

// Adds photo i to a bracket (`group`, photos of one pose). A bracket merges exposures of one pose and
// one light, so each of its photos must differ in exposure (exposure_s x gain): two photos of the same
// pose and exposure are not a bracket (photos under different lights, or the same photo twice), and
// averaging them would corrupt the samples silently. A bracket holds at most 255 exposures.
void JoinBracket(const Session& session, size_t i, std::vector<size_t>* group) {
  const PhotoSpec& photo = session.photos[i];
  const double exposure = photo.exposure_s * photo.gain;
  const std::string where = session.manifest_path + ": /photos/" + std::to_string(i);
  for (size_t j : *group) {
    const PhotoSpec& other = session.photos[j];
    const double other_exposure = other.exposure_s * other.gain;
    if (std::abs(exposure - other_exposure) <= 1e-9 * std::max(exposure, other_exposure)) {
      const Light& light = session.PhotoLight(i);
      ThrowError(where, "photos " + other.file + " (/photos/" + std::to_string(j) + ") and " + photo.file +
                            " have the same camera pose, the same light" +
                            (light.id.empty() ? std::string() : " (" + light.id + ")") +
                            " and the same exposure (exposure_s x gain = " + std::to_string(exposure) +
                            "), so they are not an exposure bracket; photos of one pose under different lights "
                            "are separate measurements (name each photo's light, session format version 2), and "
                            "a repeated photo should be left out");
    }
  }
  if (group->size() >= 255) {
    ThrowError(where, "photo " + photo.file + " would be exposure 256 of one camera pose; a bracket holds at most 255");
  }
  group->push_back(i);
}

}  // namespace

std::vector<std::vector<size_t>> ExposureGroups(const Session& session) {
  std::vector<std::vector<size_t>> groups;
  std::map<int, size_t> bracket_group;  // bracket id -> group
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    if (photo.role == PhotoRole::kTargets) continue;
    if (photo.bracket) {
      const auto it = bracket_group.find(*photo.bracket);
      if (it == bracket_group.end()) {
        bracket_group[*photo.bracket] = groups.size();
        groups.push_back({i});
        continue;
      }
      std::vector<size_t>& group = groups[it->second];
      const PhotoSpec& first = session.photos[group.front()];
      if (photo.light != first.light) {
        ThrowError(session.manifest_path + ": /photos/" + std::to_string(i) + "/bracket",
                   "photo " + photo.file + " is in bracket " + std::to_string(*photo.bracket) + " with photo " +
                       first.file + " but it was taken under " + LightLabel(session.PhotoLight(i)) + " and " +
                       first.file + " under " + LightLabel(session.PhotoLight(group.front())) +
                       " (a bracket is one camera pose under one light)");
      }
      if (first.camera_from_world && photo.camera_from_world) {
        const double translation = (first.camera_from_world->translation - photo.camera_from_world->translation).norm();
        const double rotation = first.camera_from_world->rotation.angularDistance(photo.camera_from_world->rotation);
        if (translation > kBracketMaxTranslation || rotation > kBracketMaxRotation) {
          ThrowError(session.manifest_path + ": /photos/" + std::to_string(i) + "/bracket",
                     "photo " + photo.file + " is in bracket " + std::to_string(*photo.bracket) + " with photo " +
                         first.file + " but their poses differ by " + std::to_string(translation * 1e3) + " mm and " +
                         std::to_string(rotation * 180.0 / M_PI) + " degrees (a bracket is one camera pose)");
        }
      }
      JoinBracket(session, i, &group);
      continue;
    }
    // No bracket id: identical poses under the same light are one bracket.
    bool joined = false;
    if (photo.camera_from_world) {
      for (std::vector<size_t>& group : groups) {
        const PhotoSpec& first = session.photos[group.front()];
        if (!first.bracket && first.light == photo.light && first.camera_from_world &&
            SamePose(*first.camera_from_world, *photo.camera_from_world)) {
          JoinBracket(session, i, &group);
          joined = true;
          break;
        }
      }
    }
    if (!joined) groups.push_back({i});
  }
  return groups;
}

struct RadianceReader::Impl {
  RadiometrySpec radiometry;
  std::string directory;
  int width = 0, height = 0;
  bool linear = false;             // a linear response: file values are the signal (no call per value)
  bool table = false;              // use the lookup table (non-linear responses)
  double quantization_step = 0.0;  // one file step, 1 / (2^bits - 1), with a noise model of bits > 0
  std::vector<double> to_linear;   // response^-1 at kTableIntervals + 1 nodes over [0, 1]
  std::shared_ptr<const FlatField> flat;

  double ToLinear(double encoded) const {
    if (linear) return encoded;  // Response::ToLinear of a linear response
    if (!table || !(encoded >= kTableStart && encoded <= 1.0)) return radiometry.response.ToLinear(encoded);
    const double x = encoded * kTableIntervals;
    const int i = std::min(static_cast<int>(x), kTableIntervals - 1);
    const double t = x - i;
    return to_linear[i] + t * (to_linear[i + 1] - to_linear[i]);
  }

  // Variance of a linear signal (normalized units) from the camera noise model: shot noise
  // signal / full_well, read noise (read / full_well)^2, and the file's quantization step through the
  // slope of the response at the encoded value.
  double SignalVariance(double encoded, double signal) const {
    const CameraNoise& noise = *radiometry.noise;
    const double read = noise.read_noise_e / noise.full_well_e;
    double variance = std::max(signal, 0.0) / noise.full_well_e + read * read;
    if (noise.bits > 0) {
      const double step = quantization_step;
      const double slope =
          (ToLinear(std::min(encoded + 0.5 * step, 1.0)) - ToLinear(std::max(encoded - 0.5 * step, 0.0))) / step;
      variance += (step * slope) * (step * slope) / 12.0;
    }
    return variance;
  }
};

RadianceReader::RadianceReader(const Session& session) : impl_(std::make_unique<Impl>()) {
  Impl& impl = *impl_;
  impl.radiometry = session.radiometry;
  impl.directory = session.directory;
  impl.width = session.camera.width;
  impl.height = session.camera.height;
  if (session.radiometry.response.kind == Response::Kind::kUnknown) {
    ThrowError(session.manifest_path + ": /radiometry/response",
               "is \"unknown\": the photos cannot be read linearly until the camera's response is measured "
               "(`ibrdf response SESSION --out DIR`, from exposure brackets) or stated");
  }
  impl.linear = session.radiometry.response.kind == Response::Kind::kLinear;
  impl.table = !impl.linear;
  if (session.radiometry.noise && session.radiometry.noise->bits > 0) {
    impl.quantization_step = 1.0 / (std::ldexp(1.0, session.radiometry.noise->bits) - 1.0);
  }
  if (impl.table) {
    impl.to_linear.resize(kTableIntervals + 1);
    for (int i = 0; i <= kTableIntervals; ++i) {
      impl.to_linear[i] = session.radiometry.response.ToLinear(double(i) / kTableIntervals);
    }
  }
  if (!session.radiometry.flat_field.empty()) impl.flat = LoadFlatField(session);
}

RadianceReader::~RadianceReader() = default;

double RadianceReader::Linear(double encoded) const { return impl_->ToLinear(encoded) - impl_->radiometry.black_level; }

RadianceImage RadianceReader::Read(const std::vector<PhotoSpec>& exposures, double min_signal, double* decode_s) const {
  std::vector<Image> decoded;
  RadianceImage out;
  ReadWindow(exposures, min_signal, PixelWindow{0, 0, impl_->width, impl_->height}, &decoded, &out, decode_s);
  return out;
}

// The exposures of one pose prepared inside a window: what the per-pixel merge reads besides the
// decoded files (RadianceReader::Prepare), and the merge itself.
struct RadianceReader::Exposures {
  const Impl* impl = nullptr;
  const Image* images = nullptr;  // m decoded files
  size_t m = 0;
  PixelWindow window;
  int window_width = 0, window_height = 0;
  size_t area = 0;
  double min_signal = 0.0;
  bool noise = false;
  const float* inverse_flat = nullptr;
  std::vector<double> saturation;   // per exposure: float files have none unless the session states one
  std::vector<double> scale;        // per exposure: exposure_s * gain
  const float* expected = nullptr;  // 3 * area per exposure: the mean linear signal over the floor's ring

  // The merged reading of pixel (x, y) inside the window and, with kPixelFlags, its per-pixel flags
  // (every channel, own values).
  template <bool kPixelFlags>
  void Merge(int x, int y, PixelRadiance* out, uint8_t* pixel_flags) const;
};

template <bool kPixelFlags>
void RadianceReader::Exposures::Merge(int x, int y, PixelRadiance* out, uint8_t* pixel_flags) const {
  const RadiometrySpec& radiometry = impl->radiometry;
  const size_t p = size_t(y) * impl->width + x;
  const size_t q = size_t(y - window.y0) * window_width + (x - window.x0);
  // Per exposure of the pixel (a bracket holds at most 255).
  double encoded[3 * 255], radiance[3 * 255];
  uint8_t flags[255], channel[3 * 255];
  double inverse[3] = {1.0, 1.0, 1.0};
  if (inverse_flat) {
    for (int c = 0; c < 3; ++c) inverse[c] = inverse_flat[3 * p + c];
  }
  // Each exposure on its own: the pixel's flags (every channel, own values), each channel's flags
  // (the floor on the expected signal) and the radiance.
  uint8_t all_flags = 0xff;
  bool any_clean = false;
  for (size_t e = 0; e < m; ++e) {
    const Image& image = images[e];
    const float* values = &image.pixels[p * image.channels];
    bool finite = true, saturated = false;
    double darkest = 1e300;
    for (int c = 0; c < 3; ++c) {
      const double v = values[image.channels == 1 ? 0 : c];
      encoded[3 * e + c] = v;
      const bool finite_c = std::isfinite(v);
      const bool saturated_c = v >= saturation[e];
      const double linear_c = impl->ToLinear(v) - radiometry.black_level;
      if (kPixelFlags) {
        finite = finite && finite_c;
        saturated = saturated || saturated_c;
        darkest = std::min(darkest, linear_c);
      }
      radiance[3 * e + c] = linear_c / scale[e] * inverse[c];
      uint8_t fc = 0;
      if (!finite_c) fc |= kPixelNonFinite;
      if (saturated_c) fc |= kPixelSaturated;
      if (!(expected[3 * (area * e + q) + c] >= min_signal)) fc |= kPixelBelowSignal;
      channel[3 * e + c] = fc;
    }
    if (kPixelFlags) {
      uint8_t f = 0;
      if (!finite) f |= kPixelNonFinite;
      if (saturated) f |= kPixelSaturated;
      if (!(darkest >= min_signal)) f |= kPixelBelowSignal;
      flags[e] = f;
      all_flags &= f;
      any_clean = any_clean || f == 0;
    }
  }
  if (kPixelFlags) {
    if (any_clean) {
      *pixel_flags = 0;
    } else {
      // No exposure with every channel usable: the reasons every exposure shares, or for mixed
      // reasons the one a longer exposure would not fix (clipping) before the one it would (the floor).
      uint8_t f = all_flags;
      if (f == 0) {
        bool any_saturated = false;
        for (size_t e = 0; e < m; ++e) any_saturated = any_saturated || (flags[e] & kPixelSaturated);
        f = any_saturated ? kPixelSaturated : kPixelBelowSignal;
      }
      *pixel_flags = f;
    }
  }
  int used = 0;
  for (int c = 0; c < 3; ++c) {
    // `best` is the exposure usable in this channel with the most signal (the longest), the
    // reference for the noise model's weights.
    int best = -1, longest = 0;
    uint8_t shared = 0xff;
    bool any_saturated = false;
    for (size_t e = 0; e < m; ++e) {
      const uint8_t fc = channel[3 * e + c];
      shared &= fc;
      any_saturated = any_saturated || (fc & kPixelSaturated);
      if (scale[e] > scale[longest]) longest = int(e);
      if (fc == 0 && (best < 0 || scale[e] > scale[best])) best = int(e);
    }
    if (best < 0) {
      const uint8_t mixed = any_saturated ? kPixelSaturated : kPixelBelowSignal;
      out->channel_flags[c] = shared != 0 ? shared : mixed;
      out->radiance[c] = static_cast<float>(radiance[3 * longest + c]);
      out->sigma[c] = 0.0f;
      continue;
    }
    // Inverse-variance weights, the variance predicted from the reference radiance (not from
    // each exposure's own noisy value, which would favour exposures that happened to read low).
    const double reference = radiance[3 * best + c];
    double weight_sum = 0.0, weighted = 0.0;
    int used_c = 0;
    for (size_t e = 0; e < m; ++e) {
      if (channel[3 * e + c] != 0) continue;
      double weight;
      if (noise) {
        const double to_radiance = inverse[c] / scale[e];
        const double signal = reference / to_radiance;
        weight = 1.0 / (impl->SignalVariance(encoded[3 * e + c], signal) * to_radiance * to_radiance);
      } else {
        weight = scale[e] * scale[e];  // equal signal noise: radiance variance ~ 1 / scale^2
      }
      weight_sum += weight;
      weighted += weight * radiance[3 * e + c];
      ++used_c;
    }
    const double merged = weighted / weight_sum;
    out->radiance[c] = static_cast<float>(merged);
    out->sigma[c] = noise ? static_cast<float>(1.0 / std::sqrt(weight_sum)) : 0.0f;
    // A negative radiance (noise around a tiny signal after the black level) is no measurement of
    // a non-negative BRDF: flagged as below the floor (rare where the expected signal passes it).
    out->channel_flags[c] = merged >= 0.0 ? uint8_t(0) : uint8_t(kPixelBelowSignal);
    if (merged >= 0.0) used = std::max(used, used_c);
  }
  // As RadianceImage::exposures_used for a bracket; a single photo is one exposure.
  out->exposures = m > 1 ? static_cast<uint8_t>(used) : uint8_t(1);
}

namespace {

// The pixels of the floor's ring (kFloorRing*) in one dimension around index k of `size`.
int RingSpan(int k, int half, int size) { return std::min(k + half, size - 1) - std::max(k - half, 0) + 1; }

// The ring's pixel counts by column of a window `width` wide (outer and inner span), and of each value
// of a row at least kFloorRingOuter rows from the window's top and bottom; the columns whose ring lies
// inside the window.
struct RingColumns {
  explicit RingColumns(int width) : span_outer_x(width), span_inner_x(width), interior_row_count(3 * size_t(width)) {
    constexpr int kOuter = kFloorRingOuter, kInner = kFloorRingInner;
    for (int i = 0; i < width; ++i) {
      span_outer_x[i] = RingSpan(i, kOuter, width);
      span_inner_x[i] = RingSpan(i, kInner, width);
    }
    interior_begin = std::min(kOuter, width);
    interior_end = std::max(width - kOuter, interior_begin);
    for (int i = 0; i < width; ++i) {
      for (int c = 0; c < 3; ++c) {
        interior_row_count[3 * i + c] = span_outer_x[i] * (2 * kOuter + 1) - span_inner_x[i] * (2 * kInner + 1);
      }
    }
  }
  std::vector<int> span_outer_x, span_inner_x, interior_row_count;
  int interior_begin = 0, interior_end = 0;
};

// The linear signal and the horizontal sums of a block of rows and its kFloorRingOuter rows above and
// below, small enough to stay in cache (the blocks' halo rows are computed twice).
struct RingRowBuffers {
  std::vector<float> linear, outer, inner;
};

}  // namespace

void RadianceReader::Decode(const std::vector<PhotoSpec>& exposures, const PixelWindow& window,
                            std::vector<Image>* decoded, Exposures* state, double* decode_s) const {
  IBRDF_CHECK(!exposures.empty());
  IBRDF_CHECK(exposures.size() < 256) << exposures.size() << " exposures";
  const Impl& impl = *impl_;
  IBRDF_CHECK(window.x0 >= 0 && window.y0 >= 0 && window.x1 <= impl.width && window.y1 <= impl.height);
  const RadiometrySpec& radiometry = impl.radiometry;
  const size_t m = exposures.size();
  std::vector<Image>& images = *decoded;
  if (images.size() < m) images.resize(m);
  Exposures& st = *state;
  st.impl = &impl;
  st.images = images.data();
  st.m = m;
  st.window = window;
  st.noise = radiometry.noise.has_value();
  st.inverse_flat = impl.flat ? impl.flat->inverse.data() : nullptr;
  st.saturation.assign(m, 0.0);
  st.scale.assign(m, 0.0);
  for (size_t e = 0; e < m; ++e) {
    const std::string path = ResolvePath(impl.directory, exposures[e].file);
    Timer timer;
    ReserveWithHugePages(&images[e].pixels, 3 * size_t(impl.width) * impl.height);
    // Only the window is read below (the floor's ring and the merge stay inside it): a PNG is
    // converted there only and decoded no further than its last row.
    ReadImageRegion(path, ImageRegion{window.x0, window.y0, window.x1, window.y1}, &images[e]);
    if (decode_s) *decode_s += timer.ElapsedSeconds();
    if (images[e].width != impl.width || images[e].height != impl.height) {
      ThrowError(path, "is " + std::to_string(images[e].width) + "x" + std::to_string(images[e].height) +
                           ", the camera is " + std::to_string(impl.width) + "x" + std::to_string(impl.height));
    }
    if (images[e].channels != 1 && images[e].channels < 3) {
      ThrowError(path, "expected 1 (grey) or 3+ (RGB) channels, got " + std::to_string(images[e].channels));
    }
    st.scale[e] = exposures[e].exposure_s * exposures[e].gain;
    st.saturation[e] = SaturationLevel(radiometry, images[e]);
  }
}

void RadianceReader::Prepare(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
                             std::vector<Image>* decoded, std::vector<float>* scratch_buffer, Exposures* state,
                             double* decode_s) const {
  const Impl& impl = *impl_;
  const RadiometrySpec& radiometry = impl.radiometry;
  const size_t m = exposures.size();
  Decode(exposures, window, decoded, state, decode_s);
  const std::vector<Image>& images = *decoded;
  Exposures& st = *state;
  st.min_signal = min_signal;

  // The expected signal of every channel in every exposure: the mean linear signal over the ring of
  // neighbours (kFloorRing*), by separable box sums over the window (5x5 minus 3x3). The sums run in
  // the same order at the window's edges and inside it (the inside's loops only drop the bounds
  // tests, so the compiler can vectorize them), so the values do not depend on the window.
  const int width = window.x1 - window.x0, height = window.y1 - window.y0;
  st.window_width = std::max(width, 0);
  st.window_height = std::max(height, 0);
  const size_t area = size_t(st.window_width) * st.window_height;
  st.area = area;
  // Every element is written before it is read, so the scratch memory is only grown, never cleared.
  std::vector<float>& scratch = *scratch_buffer;
  if (scratch.size() < 3 * area * m) {
    // Room for a whole frame at once: a later, larger window does not regrow it into fresh pages.
    ReserveWithHugePages(&scratch, 3 * size_t(impl.width) * impl.height * m);
    scratch.resize(3 * area * m);
  }
  float* const expected = scratch.data();
  st.expected = expected;
  if (area == 0) return;
  constexpr int kOuter = kFloorRingOuter, kInner = kFloorRingInner;
  // Neighbours on one side: the loops below spell the ring's sums out for these half-widths.
  static_assert(kOuter == 2 && kInner == 1, "the ring's sums are written for a 5x5 square without its 3x3");
  // Ring pixel counts by column; rows are done per row.
  const RingColumns columns(width);
  const std::vector<int>&span_outer_x = columns.span_outer_x, &span_inner_x = columns.span_inner_x;
  const std::vector<int>& interior_row_count = columns.interior_row_count;
  const int interior_begin = columns.interior_begin, interior_end = columns.interior_end;
  const size_t row_values = 3 * size_t(width);
  // Per thread and kept for the process (sized for a whole block at once): fresh buffers for every
  // photo were a third of the stage's page faults.
  static thread_local RingRowBuffers thread_buffers;
  constexpr int kBlockRows = 32;
  const size_t block_values = row_values * size_t(kBlockRows + 2 * kOuter);
  for (size_t e = 0; e < m; ++e) {
    const Image& image = images[e];
    float* exp = &expected[3 * area * e];
    tbb::parallel_for(tbb::blocked_range<int>(0, height, kBlockRows), [&](const tbb::blocked_range<int>& rows) {
      const int first = std::max(rows.begin() - kOuter, 0), last = std::min(rows.end() + kOuter, height);
      RingRowBuffers& local = thread_buffers;
      if (local.linear.size() < block_values) {
        local.linear.resize(block_values);
        local.outer.resize(block_values);
        local.inner.resize(block_values);
      }
      // The linear signal and the horizontal sums of rows first .. last - 1.
      for (int j = first; j < last; ++j) {
        float* row = &local.linear[row_values * (j - first)];
        const float* values = &image.pixels[(size_t(j + window.y0) * impl.width + window.x0) * image.channels];
        if (image.channels == 3 && impl.linear) {
          const double black = radiometry.black_level;
          for (size_t k = 0; k < row_values; ++k) {
            const double v = values[k];
            row[k] = static_cast<float>(std::isfinite(v) ? v - black : 0.0);
          }
        } else {
          for (int i = 0; i < width; ++i) {
            for (int c = 0; c < 3; ++c) {
              const double v = values[i * image.channels + (image.channels == 1 ? 0 : c)];
              const double l = std::isfinite(v) ? impl.ToLinear(v) - radiometry.black_level : 0.0;
              row[3 * i + c] = static_cast<float>(l);
            }
          }
        }
        float* row_outer = &local.outer[row_values * (j - first)];
        float* row_inner = &local.inner[row_values * (j - first)];
        const auto edge = [&](int i) {
          for (int c = 0; c < 3; ++c) {
            double sum_outer = 0.0, sum_inner = 0.0;
            for (int d = -kOuter; d <= kOuter; ++d) {
              if (i + d < 0 || i + d >= width) continue;
              const double l = row[3 * (i + d) + c];
              sum_outer += l;
              if (std::abs(d) <= kInner) sum_inner += l;
            }
            row_outer[3 * i + c] = static_cast<float>(sum_outer);
            row_inner[3 * i + c] = static_cast<float>(sum_inner);
          }
        };
        for (int i = 0; i < interior_begin; ++i) edge(i);
        for (int k = 3 * interior_begin; k < 3 * interior_end; ++k) {
          const double l2 = row[k - 6], l1 = row[k - 3], l0 = row[k], r1 = row[k + 3], r2 = row[k + 6];
          double sum_outer = 0.0;
          sum_outer += l2;
          sum_outer += l1;
          sum_outer += l0;
          sum_outer += r1;
          sum_outer += r2;
          double sum_inner = 0.0;
          sum_inner += l1;
          sum_inner += l0;
          sum_inner += r1;
          row_outer[k] = static_cast<float>(sum_outer);
          row_inner[k] = static_cast<float>(sum_inner);
        }
        for (int i = interior_end; i < width; ++i) edge(i);
      }
      // Vertical sums and the mean, rows of the block.
      const auto outer_at = [&](int j) { return &local.outer[row_values * (j - first)]; };
      const auto inner_at = [&](int j) { return &local.inner[row_values * (j - first)]; };
      for (int j = rows.begin(); j < rows.end(); ++j) {
        const int span_outer_y = RingSpan(j, kOuter, height), span_inner_y = RingSpan(j, kInner, height);
        float* row_exp = &exp[row_values * j];
        const float* row_lin = &local.linear[row_values * (j - first)];
        if (j >= kOuter && j + kOuter < height) {
          const float *o0 = outer_at(j - 2), *o1 = outer_at(j - 1), *o2 = outer_at(j), *o3 = outer_at(j + 1),
                      *o4 = outer_at(j + 2);
          const float *n0 = inner_at(j - 1), *n1 = inner_at(j), *n2 = inner_at(j + 1);
          for (size_t k = 0; k < row_values; ++k) {
            double ring = 0.0;
            ring += o0[k];
            ring += o1[k];
            ring -= n0[k];
            ring += o2[k];
            ring -= n1[k];
            ring += o3[k];
            ring -= n2[k];
            ring += o4[k];
            // A window too small for any ring pixel: the pixel's own value.
            const int count = interior_row_count[k];
            row_exp[k] = count > 0 ? static_cast<float>(ring / count) : row_lin[k];
          }
          continue;
        }
        for (int i = 0; i < width; ++i) {
          const int count = span_outer_x[i] * span_outer_y - span_inner_x[i] * span_inner_y;
          for (int c = 0; c < 3; ++c) {
            double ring = 0.0;
            for (int d = -kOuter; d <= kOuter; ++d) {
              if (j + d < 0 || j + d >= height) continue;
              ring += outer_at(j + d)[3 * i + c];
              if (std::abs(d) <= kInner) ring -= inner_at(j + d)[3 * i + c];
            }
            // A window too small for any ring pixel (a 1x1 window): the pixel's own value.
            row_exp[3 * i + c] = count > 0 ? static_cast<float>(ring / count) : row_lin[3 * i + c];
          }
        }
      }
    });
  }
}

void RadianceReader::ReadWindow(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
                                std::vector<Image>* decoded, RadianceImage* radiance_image, double* decode_s) const {
  Exposures st;
  Prepare(exposures, min_signal, window, decoded, &radiance_image->scratch, &st, decode_s);
  const Impl& impl = *impl_;
  const size_t m = exposures.size();
  RadianceImage& out = *radiance_image;
  out.width = impl.width;
  out.height = impl.height;
  const size_t n = size_t(impl.width) * impl.height;
  // Sized once; every pixel of the window is written below (sigma and exposures_used included), so
  // nothing needs clearing between photos.
  ReserveWithHugePages(&out.radiance, 3 * n);
  ReserveWithHugePages(&out.sigma, 3 * n);
  out.radiance.resize(3 * n);
  out.sigma.resize(3 * n);
  out.flags.resize(n);
  if (m > 1) {
    out.exposures_used.resize(n);
  } else {
    out.exposures_used.clear();
  }
  out.channel_flags.resize(3 * n);
  tbb::parallel_for(tbb::blocked_range<int>(window.y0, window.y1), [&](const tbb::blocked_range<int>& rows) {
    PixelRadiance pixel;
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = window.x0; x < window.x1; ++x) {
        const size_t p = size_t(y) * impl.width + x;
        st.Merge<true>(x, y, &pixel, &out.flags[p]);
        for (int c = 0; c < 3; ++c) {
          out.radiance[3 * p + c] = pixel.radiance[c];
          out.sigma[3 * p + c] = pixel.sigma[c];
          out.channel_flags[3 * p + c] = pixel.channel_flags[c];
        }
        if (m > 1) out.exposures_used[p] = pixel.exposures;
      }
    }
  });
}

void RadianceReader::PrepareWindow(const std::vector<PhotoSpec>& exposures, double min_signal,
                                   const PixelWindow& window, RadianceWindow* out, double* decode_s) const {
  if (!out->state_) out->state_ = std::make_unique<Exposures>();
  Prepare(exposures, min_signal, window, &out->decoded_, &out->scratch_, out->state_.get(), decode_s);
}

RadianceWindow::RadianceWindow() = default;
RadianceWindow::~RadianceWindow() = default;

void RadianceWindow::At(int x, int y, PixelRadiance* out) const { state_->Merge<false>(x, y, out, nullptr); }

int RadianceWindow::width() const { return state_->impl->width; }
int RadianceWindow::height() const { return state_->impl->height; }
const PixelWindow& RadianceWindow::window() const { return state_->window; }

RadianceImage ReadRadianceImage(const Session& session, const std::vector<size_t>& group, double min_signal,
                                double* decode_s) {
  std::vector<PhotoSpec> exposures;
  for (size_t i : group) exposures.push_back(session.photos.at(i));
  return RadianceReader(session).Read(exposures, min_signal, decode_s);
}

}  // namespace ibrdf
