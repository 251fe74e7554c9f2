#include "derender/radiance_image.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/linear_image.h"
#include "core/logging.h"
#include "derender/huge_pages.h"

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
  bool linear = false;            // a linear response: file values are the signal (no call per value)
  bool table = false;             // use the lookup table (non-linear responses)
  double quantization_step = 0.0;  // one file step, 1 / (2^bits - 1), with a noise model of bits > 0
  std::vector<double> to_linear;  // response^-1 at kTableIntervals + 1 nodes over [0, 1]
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

void RadianceReader::ReadWindow(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
                                std::vector<Image>* decoded, RadianceImage* radiance_image, double* decode_s) const {
  IBRDF_CHECK(!exposures.empty());
  IBRDF_CHECK(exposures.size() < 256) << exposures.size() << " exposures";
  const Impl& impl = *impl_;
  IBRDF_CHECK(window.x0 >= 0 && window.y0 >= 0 && window.x1 <= impl.width && window.y1 <= impl.height);
  const RadiometrySpec& radiometry = impl.radiometry;
  const size_t m = exposures.size();
  std::vector<Image>& images = *decoded;
  if (images.size() < m) images.resize(m);
  std::vector<double> saturation(m);  // per exposure: float files have none unless the session states one
  std::vector<double> scale(m);  // exposure_s * gain
  for (size_t e = 0; e < m; ++e) {
    const std::string path = ResolvePath(impl.directory, exposures[e].file);
    Timer timer;
    ReserveWithHugePages(&images[e].pixels, 3 * size_t(impl.width) * impl.height);
    ReadImage(path, &images[e]);
    if (decode_s) *decode_s += timer.ElapsedSeconds();
    if (images[e].width != impl.width || images[e].height != impl.height) {
      ThrowError(path, "is " + std::to_string(images[e].width) + "x" + std::to_string(images[e].height) +
                           ", the camera is " + std::to_string(impl.width) + "x" + std::to_string(impl.height));
    }
    if (images[e].channels != 1 && images[e].channels < 3) {
      ThrowError(path, "expected 1 (grey) or 3+ (RGB) channels, got " + std::to_string(images[e].channels));
    }
    scale[e] = exposures[e].exposure_s * exposures[e].gain;
    saturation[e] = SaturationLevel(radiometry, images[e]);
  }
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
  const bool noise = radiometry.noise.has_value();
  const float* inverse_flat = impl.flat ? impl.flat->inverse.data() : nullptr;

  tbb::parallel_for(tbb::blocked_range<int>(window.y0, window.y1), [&](const tbb::blocked_range<int>& rows) {
    // Per exposure of the pixel being worked on.
    std::vector<double> encoded(3 * m), radiance(3 * m);
    std::vector<uint8_t> flags(m);
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = window.x0; x < window.x1; ++x) {
        const size_t p = size_t(y) * impl.width + x;
        double inverse[3] = {1.0, 1.0, 1.0};
        if (inverse_flat) {
          for (int c = 0; c < 3; ++c) inverse[c] = inverse_flat[3 * p + c];
        }
        // Each exposure on its own: flags and radiance. `best` is the usable exposure with the most
        // signal (the longest), the reference for the noise model's weights.
        int best = -1;
        uint8_t all_flags = 0xff;
        for (size_t e = 0; e < m; ++e) {
          const Image& image = images[e];
          const float* values = &image.pixels[p * image.channels];
          bool finite = true, saturated = false;
          double darkest = 1e300;
          for (int c = 0; c < 3; ++c) {
            const double v = values[image.channels == 1 ? 0 : c];
            encoded[3 * e + c] = v;
            finite = finite && std::isfinite(v);
            saturated = saturated || v >= saturation[e];
            const double linear = impl.ToLinear(v) - radiometry.black_level;
            darkest = std::min(darkest, linear);
            radiance[3 * e + c] = linear / scale[e] * inverse[c];
          }
          uint8_t f = 0;
          if (!finite) f |= kPixelNonFinite;
          if (saturated) f |= kPixelSaturated;
          if (!(darkest >= min_signal)) f |= kPixelBelowSignal;
          flags[e] = f;
          all_flags &= f;
          if (f == 0 && (best < 0 || scale[e] > scale[best])) best = int(e);
        }
        if (best < 0) {
          // No usable exposure: the reasons every exposure shares, or for mixed reasons the one a
          // longer exposure would not fix (clipping) before the one it would (the floor).
          uint8_t f = all_flags;
          if (f == 0) {
            bool any_saturated = false;
            for (size_t e = 0; e < m; ++e) any_saturated = any_saturated || (flags[e] & kPixelSaturated);
            f = any_saturated ? kPixelSaturated : kPixelBelowSignal;
          }
          out.flags[p] = f;
          for (int c = 0; c < 3; ++c) {
            out.radiance[3 * p + c] = static_cast<float>(radiance[c]);
            out.sigma[3 * p + c] = 0.0f;
          }
          if (m > 1) out.exposures_used[p] = 0;
          continue;
        }
        int used = 0;
        for (int c = 0; c < 3; ++c) {
          // Inverse-variance weights, the variance predicted from the reference radiance (not from
          // each exposure's own noisy value, which would favour exposures that happened to read low).
          const double reference = radiance[3 * best + c];
          double weight_sum = 0.0, weighted = 0.0;
          for (size_t e = 0; e < m; ++e) {
            if (flags[e] != 0) continue;
            double weight;
            if (noise) {
              const double to_radiance = inverse[c] / scale[e];
              const double signal = reference / to_radiance;
              weight = 1.0 / (impl.SignalVariance(encoded[3 * e + c], signal) * to_radiance * to_radiance);
            } else {
              weight = scale[e] * scale[e];  // equal signal noise: radiance variance ~ 1 / scale^2
            }
            weight_sum += weight;
            weighted += weight * radiance[3 * e + c];
            used += c == 0;
          }
          out.radiance[3 * p + c] = static_cast<float>(weighted / weight_sum);
          out.sigma[3 * p + c] = noise ? static_cast<float>(1.0 / std::sqrt(weight_sum)) : 0.0f;
        }
        out.flags[p] = 0;
        if (m > 1) out.exposures_used[p] = static_cast<uint8_t>(used);
      }
    }
  });
}

RadianceImage ReadRadianceImage(const Session& session, const std::vector<size_t>& group, double min_signal,
                                double* decode_s) {
  std::vector<PhotoSpec> exposures;
  for (size_t i : group) exposures.push_back(session.photos.at(i));
  return RadianceReader(session).Read(exposures, min_signal, decode_s);
}

}  // namespace ibrdf
