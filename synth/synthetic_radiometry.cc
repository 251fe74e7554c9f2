#include "synth/synthetic_radiometry.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>

#include <tbb/parallel_for.h>

#include "align/markers.h"
#include "core/error.h"
#include "core/light.h"
#include "core/radiometry.h"
#include "core/statistics.h"
#include "synth/noise_random.h"
#include "synth/photo_png.h"
#include "synth/pixel_rays.h"
#include "synth/synthetic_colour_chart.h"
#include "synth/synthetic_exif.h"
#include "synth/synthetic_targets.h"

namespace fs = std::filesystem;

namespace ibrdf {

namespace {
constexpr double kToeShoulderPower = 1.6, kToeShoulderKnee = 0.25;
}  // namespace

double ToeShoulderEncode(double x) {
  if (x <= 0.0) return 0.0;
  const double p = std::pow(x, kToeShoulderPower);
  return (1.0 + kToeShoulderKnee) * p / (p + kToeShoulderKnee);
}

double ToeShoulderDecode(double v) {
  if (v <= 0.0) return 0.0;
  // v (x^a + k) = (1 + k) x^a  =>  x^a = v k / (1 + k - v).
  return std::pow(v * kToeShoulderKnee / (1.0 + kToeShoulderKnee - v), 1.0 / kToeShoulderPower);
}

double EncodeSensorCurve(SensorCurve curve, double linear) {
  switch (curve) {
    case SensorCurve::kLinear:
      return linear;
    case SensorCurve::kSrgb:
      return LinearToSrgb(linear);
    case SensorCurve::kToeShoulder:
      return ToeShoulderEncode(linear);
  }
  UnhandledKind("SensorCurve", static_cast<int>(curve));
}

double VignettingAt(const Camera& camera, double strength, double x, double y) {
  if (strength <= 0.0) return 1.0;
  const double cx = camera.PrincipalX(), cy = camera.PrincipalY();
  const double corner2 = std::max(cx * cx, (camera.width - cx) * (camera.width - cx)) +
                         std::max(cy * cy, (camera.height - cy) * (camera.height - cy));
  const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / corner2;
  const double tan2 = 1.0 / std::sqrt(1.0 - strength) - 1.0;  // cos^4(a) = 1 - strength
  const double q = 1.0 + r2 * tan2;
  return 1.0 / (q * q);
}

void ApplyVignetting(const Camera& camera, double strength, Image* signal) {
  if (strength <= 0.0) return;
  tbb::parallel_for(0, signal->height, [&](int y) {
    for (int x = 0; x < signal->width; ++x) {
      const float v = static_cast<float>(VignettingAt(camera, strength, x + 0.5, y + 0.5));
      for (int c = 0; c < signal->channels; ++c) signal->at(x, y, c) *= v;
    }
  });
}

uint64_t SimulateSensor(const CameraEffects& effects, uint64_t seed, uint64_t stream, Image* signal) {
  Image& image = *signal;
  const double levels_max = effects.bits > 0 ? std::ldexp(1.0, effects.bits) - 1.0 : 0.0;
  const double read_sigma = effects.read_noise_e / effects.full_well_e;
  std::atomic<uint64_t> clipped{0};
  tbb::parallel_for(0, image.height, [&](int y) {
    NoiseRandom rng(seed, stream, uint64_t(y));
    uint64_t row_clipped = 0;
    for (int x = 0; x < image.width; ++x) {
      bool pixel_clipped = false;
      for (int c = 0; c < image.channels; ++c) {
        double v = image.at(x, y, c);  // linear signal
        if (effects.shot_noise && v > 0.0) {
          const double electrons = v * effects.full_well_e;
          const double noisy = electrons < 1000.0 ? double(std::poisson_distribution<long>(electrons)(rng))
                                                  : electrons + std::sqrt(electrons) * rng.Normal();
          v = noisy / effects.full_well_e;
        }
        if (effects.read_noise) v += read_sigma * rng.Normal();
        v = std::max(0.0, v + effects.black_level);
        if (effects.clip && v >= 1.0) {
          v = 1.0;
          pixel_clipped = true;
        }
        v = EncodeSensorCurve(effects.curve, v);
        // Round half up (v >= 0): the truncating conversion is inline where std::round is a libm call.
        if (effects.bits > 0) v = double(int64_t(std::min(v, 1.0) * levels_max + 0.5)) / levels_max;
        image.at(x, y, c) = static_cast<float>(v);
      }
      row_clipped += pixel_clipped;
    }
    clipped += row_clipped;
  });
  return clipped;
}

void ExpandBrackets(const SynthOptions& options, Session* session) {
  const SynthRadiometryOptions& radiometry = options.radiometry;
  if (radiometry.brackets <= 1) return;
  std::vector<PhotoSpec> photos;
  int pose = 0;
  for (const PhotoSpec& photo : session->photos) {
    if (photo.role != PhotoRole::kMeasurement) {
      photos.push_back(photo);
      continue;
    }
    const fs::path file(photo.file);
    for (int k = 0; k < radiometry.brackets; ++k) {
      PhotoSpec exposure = photo;
      exposure.file =
          (file.parent_path() / (file.stem().string() + "-e" + std::to_string(k) + file.extension().string())).string();
      exposure.bracket = pose;
      exposure.exposure_s = std::exp2(-radiometry.bracket_step_ev * k);
      photos.push_back(exposure);
    }
    ++pose;
  }
  session->photos = photos;
}

namespace {

// The white reference's ideal radiance image: a square of side `size` centred at `center` with normal
// `normal`, Lambertian of albedo rho, under `light`; 0 elsewhere. `mask` gets 1 where a
// pixel centre sees it.
Image RenderWhiteReference(const Session& session, const Light& light, const Rigid3d& camera_from_world,
                           const WhiteReferenceSpec& white, int supersample, std::vector<uint8_t>* mask) {
  const Camera& camera = session.camera;
  const Eigen::Vector3d u = white.normal.unitOrthogonal(), v = white.normal.cross(u);
  mask->assign(size_t(camera.width) * camera.height, 0);
  return RenderRays(PixelRays(camera, supersample), camera_from_world,
                    [&](const Eigen::Vector3d& eye, const PixelRay& ray) -> Eigen::Vector3d {
                      double t;
                      if (!RayPlaneHit(eye, ray.direction, white.center, white.normal, &t)) {
                        return Eigen::Vector3d::Zero();
                      }
                      const Eigen::Vector3d offset = eye + t * ray.direction - white.center;
                      if (std::abs(offset.dot(u)) > 0.5 * white.size || std::abs(offset.dot(v)) > 0.5 * white.size) {
                        return Eigen::Vector3d::Zero();
                      }
                      if (ray.centre) (*mask)[ray.pixel] = 1;
                      const Incidence incidence = IncidenceAt(light, white.center + offset, white.normal);
                      if (!incidence.lit) return Eigen::Vector3d::Zero();
                      return Eigen::Vector3d(white.reflectance.cwiseProduct(incidence.irradiance) / M_PI);
                    });
}

// The white reference's marker card (SynthTargetOptions::white_card): its pose and what it looks like.
class WhiteCard {
 public:
  static constexpr double kPaper = 0.8;  // the printed card's albedo
  static constexpr double kInk = 0.03;   // the markers' black

  WhiteCard(const SynthOptions& options, const WhiteReferenceSpec& white, const Eigen::Vector3d& x_axis)
      : white_(white), x_axis_(x_axis), y_axis_(white.normal.cross(x_axis)) {
    const MarkerDictionary dictionary(options.targets.dictionary, "synth --target-dictionary");
    modules_count_ = dictionary.modules();
    markers_ = SynthWhiteCardLayout(options).markers;
    for (const TargetSpec& marker : markers_) modules_.push_back(dictionary.Modules(marker.id));
    half_side_ = 0.5 * white.size + options.targets.white_marker_size * (1.0 + 2.0 * options.targets.card_margin);
  }

  double half_side() const { return half_side_; }
  const Eigen::Vector3d& y_axis() const { return y_axis_; }

  // The card's albedo where the ray meets it (the hit point in `point`, its distance in `t`); < 0 where
  // it misses the card. The patch's albedo is channel 0's (a grey reference).
  double Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Eigen::Vector3d* point,
               double* t) const {
    if (!RayPlaneHit(origin, direction, white_.center, white_.normal, t)) return -1.0;
    *point = origin + *t * direction;
    const Eigen::Vector3d offset = *point - white_.center;
    const double x = offset.dot(x_axis_), y = offset.dot(y_axis_);
    if (std::abs(x) > half_side_ || std::abs(y) > half_side_) return -1.0;
    if (std::abs(x) <= 0.5 * white_.size && std::abs(y) <= 0.5 * white_.size) return white_.reflectance[0];
    const Eigen::Vector3d p(x, y, 0.0);
    for (size_t m = 0; m < markers_.size(); ++m) {
      const std::array<Eigen::Vector3d, 4>& c = markers_[m].corners;
      const Eigen::Vector3d u_axis = c[1] - c[0], v_axis = c[3] - c[0];
      const double u = (p - c[0]).dot(u_axis) / u_axis.squaredNorm(), v = (p - c[0]).dot(v_axis) / v_axis.squaredNorm();
      if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) continue;
      const int n = modules_count_;
      const int col = std::min(n - 1, int(u * n)), row = std::min(n - 1, int(v * n));
      return modules_[m][size_t(row) * n + col] ? kPaper : kInk;
    }
    return kPaper;
  }

 private:
  const WhiteReferenceSpec& white_;
  Eigen::Vector3d x_axis_, y_axis_;
  int modules_count_ = 0;
  double half_side_ = 0.0;
  std::vector<TargetSpec> markers_;  // card frame
  std::vector<std::vector<bool>> modules_;
};

// The card's radiance image under `light` (albedo / pi x irradiance; 0 off the card): a pixel whose
// four corners see the same albedo takes its centre's radiance, the others (edges) the mean of
// max(4, supersample)^2 rays (anti-aliased marker edges, as the platform's). `mask` gets 1 where the
// pixel centre sees the patch.
Image RenderWhiteCard(const Session& session, const Light& light, const Rigid3d& camera_from_world,
                      const WhiteCard& card, int supersample, std::vector<uint8_t>* mask) {
  const Camera& camera = session.camera;
  const CameraRay camera_ray(camera, camera_from_world);
  const Eigen::Vector3d& center = camera_ray.eye();
  const double patch_albedo = session.calibration->white_reference->reflectance[0];
  auto ray = [&](const Eigen::Vector2d& pixel) { return camera_ray.Direction(pixel); };
  // Radiance of one ray: albedo / pi x the irradiance at its hit (the patch's per-channel albedo).
  auto radiance_along = [&](const Eigen::Vector3d& direction, double* albedo) {
    Eigen::Vector3d point;
    double t;
    *albedo = card.Trace(center, direction, &point, &t);
    if (*albedo < 0.0) return Eigen::Vector3d(Eigen::Vector3d::Zero());
    const Incidence incidence = IncidenceAt(light, point, session.calibration->white_reference->normal);
    if (!incidence.lit) return Eigen::Vector3d(Eigen::Vector3d::Zero());
    const Eigen::Vector3d rho = *albedo == patch_albedo ? session.calibration->white_reference->reflectance
                                                        : Eigen::Vector3d::Constant(*albedo);
    return Eigen::Vector3d(rho.cwiseProduct(incidence.irradiance) / M_PI);
  };
  const int w = camera.width, h = camera.height;
  std::vector<double> corners(size_t(w + 1) * (h + 1));
  tbb::parallel_for(0, h + 1, [&](int y) {
    for (int x = 0; x <= w; ++x) {
      Eigen::Vector3d point;
      double t;
      corners[size_t(y) * (w + 1) + x] = card.Trace(center, ray(Eigen::Vector2d(x, y)), &point, &t);
    }
  });
  Image image(w, h, 3);
  mask->assign(size_t(w) * h, 0);
  const int rays = std::max(4, supersample);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const double c00 = corners[size_t(y) * (w + 1) + x], c10 = corners[size_t(y) * (w + 1) + x + 1];
      const double c01 = corners[size_t(y + 1) * (w + 1) + x], c11 = corners[size_t(y + 1) * (w + 1) + x + 1];
      double albedo;
      Eigen::Vector3d radiance = radiance_along(ray(Eigen::Vector2d(x + 0.5, y + 0.5)), &albedo);
      if (albedo == patch_albedo) (*mask)[size_t(y) * w + x] = 1;
      if (c00 != c10 || c00 != c01 || c00 != c11 || (supersample > 1 && albedo >= 0.0)) {
        radiance.setZero();
        for (int sy = 0; sy < rays; ++sy) {
          for (int sx = 0; sx < rays; ++sx) {
            double a;
            radiance += radiance_along(ray(Eigen::Vector2d(x + (sx + 0.5) / rays, y + (sy + 0.5) / rays)), &a);
          }
        }
        radiance /= double(rays * rays);
      }
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(radiance[c]);
    }
  });
  return image;
}

}  // namespace

void WriteSynthCalibration(const SynthOptions& options, const std::string& directory, Session* session,
                           const TargetCompositor& composite_targets) {
  const CameraEffects& effects = options.effects;
  const SynthRadiometryOptions& radiometry = options.radiometry;
  if (effects.vignetting > 0.0) {
    // The flat field a lab gets from many photos of a uniform diffuser at half of full scale, averaged
    // (64 frames): the vignetting with what remains of the shot noise.
    const Camera& camera = session->camera;
    Image flat(camera.width, camera.height, 3);
    const double noise = effects.shot_noise ? 1.0 / std::sqrt(0.5 * effects.full_well_e * 64.0) : 0.0;
    tbb::parallel_for(0, camera.height, [&](int y) {
      NoiseRandom rng(options.seed, 0xF1A7F1E1Dull, uint64_t(y));
      for (int x = 0; x < camera.width; ++x) {
        const double v = VignettingAt(camera, effects.vignetting, x + 0.5, y + 0.5);
        for (int c = 0; c < 3; ++c) flat.at(x, y, c) = static_cast<float>(v * (1.0 + noise * rng.Normal()));
      }
    });
    session->radiometry.flat_field = "flat_field.exr";
    WriteImage((fs::path(directory) / session->radiometry.flat_field).string(), flat, PixelFormat::kFloat);
  }
  if (radiometry.light_unknown) {
    const PhotoSpec* first = nullptr;
    for (const PhotoSpec& photo : session->photos) {
      if (photo.role == PhotoRole::kMeasurement && photo.camera_from_world) {
        first = &photo;
        break;
      }
    }
    IBRDF_CHECK(first != nullptr);
    WhiteReferenceSpec white;
    white.reflectance = Eigen::Vector3d::Constant(radiometry.white_reflectance);
    white.center = session->sample.center;
    white.size = radiometry.white_size;
    const Eigen::Vector3d camera_center = first->camera_from_world->Inverse().translation;
    // The target faces between the camera and the lights' mean direction (the one light's, usually).
    Eigen::Vector3d to_lights = Eigen::Vector3d::Zero();
    for (const Light& light : session->lights) {
      to_lights += DirectionToLight(light, white.center);
    }
    white.normal = (to_lights.normalized() + (camera_center - white.center).normalized()).normalized();
    // The marker card stands on a post where the sample was, its x axis level, raised so that its
    // lower edge clears the platform by 5 mm.
    const Eigen::Vector3d card_x = Eigen::Vector3d::UnitZ().cross(white.normal).normalized();
    std::unique_ptr<WhiteCard> card;
    if (options.targets.white_card) {
      card = std::make_unique<WhiteCard>(options, white, card_x);
      const double lowest = PlatformHeight(options.scene) + card->half_side() * std::abs(card->y_axis().z()) + 0.005;
      white.center.z() = std::max(white.center.z(), lowest);
    }
    const PixelFormat format = effects.bits == 0   ? PixelFormat::kFloat
                               : effects.bits <= 8 ? PixelFormat::kUint8
                                                   : PixelFormat::kUint16;
    fs::create_directories(fs::path(directory) / "calibration");
    CalibrationSpec calibration;
    calibration.white_reference = white;
    session->calibration = calibration;
    WhiteReferenceSpec& stated = *session->calibration->white_reference;  // the card reads the pose from here
    if (card) card = std::make_unique<WhiteCard>(options, stated, card_x);
    // One photo of the target under each light, exposed for it.
    for (size_t k = 0; k < session->lights.size(); ++k) {
      std::vector<uint8_t> mask;
      Image image = card ? RenderWhiteCard(*session, session->lights[k], *first->camera_from_world, *card,
                                           effects.supersample, &mask)
                         : RenderWhiteReference(*session, session->lights[k], *first->camera_from_world, white,
                                                effects.supersample, &mask);
      ApplyCameraMatrix(options.colour.camera_matrix, &image);  // the camera's RGB (synthetic_colour_chart.h)
      std::vector<float> levels;
      for (size_t p = 0; p < mask.size(); ++p) {
        if (mask[p])
          levels.push_back(std::max({image.pixels[3 * p], image.pixels[3 * p + 1], image.pixels[3 * p + 2]}));
      }
      IBRDF_CHECK(!levels.empty()) << "the white reference is out of view";
      const double level = PercentileInPlace(&levels, 0.99);
      IBRDF_CHECK(level > 0.0) << "the white reference is unlit by light " << k;
      PhotoSpec photo;
      char name[48];
      std::snprintf(name, sizeof(name), "calibration/white-%03zu.%s", k, effects.bits == 0 ? "exr" : "png");
      photo.file = name;
      photo.camera_from_world = first->camera_from_world;
      photo.exposure_s = radiometry.white_exposure_scale * options.rig.exposure_target / level;
      photo.gain = 1.0;
      photo.light = k;
      for (float& v : image.pixels) v = static_cast<float>(v * photo.exposure_s * photo.gain);
      if (card && composite_targets) {
        // The platform behind the card (its ambient-lit markers pose the photo).
        const TargetOccluder card_in_front = [&card](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                                     double t) {
          Eigen::Vector3d point;
          double t_card;
          return card->Trace(origin, direction, &point, &t_card) >= 0.0 && t_card < t;
        };
        composite_targets(*photo.camera_from_world, card_in_front, &image);
      }
      ApplyVignetting(session->camera, effects.vignetting, &image);
      SimulateSensor(effects, options.seed, 0xFFFFull + k, &image);
      const PhotoMetadata exif = SyntheticPhotoMetadata(*session, photo, session->photos.size());
      WritePhotoPng((fs::path(directory) / photo.file).string(), image, format, &exif);
      stated.photos.push_back(photo);
    }
    for (Light& light : session->lights) light.has_intensity = false;  // the white reference measures it
  }
}

}  // namespace ibrdf
