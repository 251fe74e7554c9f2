#include "synth/synthetic_mirror_sphere.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/light_json.h"
#include "core/math.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

std::string LightId(int k) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "L%02d", k);
  return buffer;
}

nlohmann::json PoseJson(const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"rotation", {q.w(), q.x(), q.y(), q.z()}}, {"translation", ToJson(pose.translation)}};
}

// Distance along the unit ray (origin o, direction d) to the sphere, or -1 for a miss.
double HitSphere(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d oc = c - o;
  const double along = oc.dot(d);
  const double off2 = (oc - along * d).squaredNorm();
  if (off2 > r * r || along <= 0) return -1.0;
  return along - std::sqrt(r * r - off2);
}

}  // namespace

bool SyntheticMirrorSphereOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(width, 16);
  IBRDF_CHECK_OPTION_GE(height, 16);
  IBRDF_CHECK_OPTION_GT(focal_px, 0.0);
  IBRDF_CHECK_OPTION_GT(radius, 0.0);
  IBRDF_CHECK_OPTION_GT(distance, 2.0 * radius + center.norm());
  IBRDF_CHECK_OPTION_RANGE(lights, 1, 999);
  IBRDF_CHECK_OPTION_RANGE(max_light_angle_deg, 0.0, 80.0);
  IBRDF_CHECK_OPTION_GT(light_distance, 10.0 * radius + center.norm());
  IBRDF_CHECK_OPTION_GT(source_sigma_deg, 0.0);
  IBRDF_CHECK_OPTION_GT(source_peak, 0.0);
  IBRDF_CHECK_OPTION_RANGE(reflectance, 0.0, 1.0);
  IBRDF_CHECK_OPTION_GE(environment, 0.0);
  IBRDF_CHECK_OPTION_GE(background, 0.0);
  IBRDF_CHECK_OPTION_RANGE(supersampling, 1, 16);
  IBRDF_CHECK_OPTION_GE(read_noise, 0.0);
  IBRDF_CHECK_OPTION_GT(full_well_e, 0.0);
  return true;
}

std::string SyntheticMirrorSphere::BriefReport() const {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "mirror sphere: %zu %s lights, %d x %d -> %s", lights.size(),
                lights.empty() ? "directional" : LightKindName(lights[0].kind), camera.width, camera.height,
                manifest.c_str());
  return buffer;
}

SyntheticMirrorSphere WriteSyntheticMirrorSphere(const SyntheticMirrorSphereOptions& options,
                                                 const std::string& out_dir, bool overwrite) {
  std::string why;
  if (!options.Check(&why)) ThrowError("mirror-sphere options", why);
  SyntheticMirrorSphere truth;
  truth.camera = Camera::Create(CameraModelId::kPinhole, options.width, options.height,
                                {options.focal_px, options.focal_px, options.width / 2.0, options.height / 2.0});
  const Eigen::Vector3d camera_center(0.0, 0.0, options.distance);
  truth.camera_from_world = LookAtCameraFromWorld(camera_center, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d world_from_camera = truth.camera_from_world.rotation.inverse().toRotationMatrix();

  // Lights on a golden-angle spiral over the cap around +z (towards the camera), rotated by the seed.
  std::mt19937_64 light_rng(options.seed);
  const double phase = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(light_rng);
  const double cos_max = std::cos(options.max_light_angle_deg * kPi / 180.0);
  for (int k = 0; k < options.lights; ++k) {
    const double cos_t = 1.0 - (1.0 - cos_max) * (k + 0.5) / options.lights;
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
    const double phi = phase + k * kPi * (3.0 - std::sqrt(5.0));
    Light light;
    truth.ids.push_back(LightId(k));
    light.id = truth.ids.back();
    light.direction = Eigen::Vector3d(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
    if (options.point_lights) {
      light.kind = Light::Kind::kPoint;
      light.position = options.light_distance * light.direction;
    } else {
      light.kind = Light::Kind::kDirectional;
    }
    truth.lights.push_back(light);
  }

  AtomicDirectory directory(out_dir, overwrite);
  const fs::path tmp(directory.temporary_path());
  fs::create_directories(tmp / "photos");
  const int w = options.width, h = options.height, ss = options.supersampling;
  const double sigma = options.source_sigma_deg * kPi / 180.0;
  const Camera& camera = truth.camera;
  auto ray_of = [&](double u, double v) {
    const Eigen::Vector2d xy = camera.CamPlaneFromImage(Eigen::Vector2d(u, v));
    return Eigen::Vector3d(world_from_camera * Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized());
  };

  // The mask: pixel centres whose ray meets the sphere.
  Image mask(w, h, 1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      mask.at(x, y, 0) =
          HitSphere(camera_center, ray_of(x + 0.5, y + 0.5), options.center, options.radius) > 0 ? 1.0f : 0.0f;
    }
  }
  WriteImage((tmp / "mask.png").string(), mask, PixelFormat::kUint8);

  nlohmann::json photos = nlohmann::json::array();
  nlohmann::json lights = nlohmann::json::array();
  for (int k = 0; k < options.lights; ++k) {
    const Light& light = truth.lights[k];
    Image image(w, h, 3);
    tbb::parallel_for(0, h, [&](int y) {
      std::mt19937_64 rng(options.seed * 1000003ull + uint64_t(k) * 7919ull + uint64_t(y));
      std::normal_distribution<double> gauss(0.0, 1.0);
      for (int x = 0; x < w; ++x) {
        double sum = 0.0;
        for (int j = 0; j < ss; ++j) {
          for (int i = 0; i < ss; ++i) {
            const Eigen::Vector3d d = ray_of(x + (i + 0.5) / ss, y + (j + 0.5) / ss);
            const double t = HitSphere(camera_center, d, options.center, options.radius);
            if (t < 0) {
              sum += options.background;
              continue;
            }
            const Eigen::Vector3d p = camera_center + t * d;
            const Eigen::Vector3d n = (p - options.center) / options.radius;
            const Eigen::Vector3d reflected = d - 2.0 * n.dot(d) * n;
            Eigen::Vector3d to_light = Eigen::Vector3d::Zero();
            switch (light.kind) {
              case Light::Kind::kPoint:
                to_light = (light.position - p).normalized();
                break;
              case Light::Kind::kDirectional:
                to_light = light.direction;
                break;
            }
            const double angle = std::atan2(reflected.cross(to_light).norm(), reflected.dot(to_light));
            double radiance = options.environment;
            if (angle < 6.0 * sigma) radiance += options.source_peak * std::exp(-0.5 * angle * angle / (sigma * sigma));
            sum += options.reflectance * radiance;
          }
        }
        const double v = sum / (ss * ss);
        const double shot = std::sqrt(std::max(0.0, v) / options.full_well_e);
        const double noisy = v + std::hypot(shot, options.read_noise) * gauss(rng);
        const float stored = float(std::clamp(noisy, 0.0, 1.0));
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = stored;
      }
    });
    const std::string& id = truth.ids[k];
    const std::string file = "photos/" + id + ".png";
    WriteImage((tmp / file).string(), image, PixelFormat::kUint8);
    photos.push_back(
        {{"file", file}, {"exposure_s", 1.0}, {"light", id}, {"camera_from_world", PoseJson(truth.camera_from_world)}});
    Light stated = light;
    stated.id = id;
    stated.intensity = Eigen::Vector3d::Ones();
    stated.has_intensity = true;
    lights.push_back(LightJson(stated));
  }

  nlohmann::json session = {
      {"format", "ibrdf-session"},
      {"version", 2},
      {"name", fs::path(out_dir).filename().string()},
      {"description",
       "synthetic mirror sphere (ibrdf lights synth): the lights' stated directions are the truth; "
       "truth-lights.json repeats them"},
      {"camera", {{"model", "PINHOLE"}, {"width", w}, {"height", h}, {"params", camera.params}}},
      {"lights", lights},
      {"mask", "mask.png"},
      {"sample", {{"kind", "sphere"}, {"center", ToJson(options.center)}, {"radius", options.radius}}},
      {"radiometry",
       {{"response", "linear"},
        {"noise",
         {{"full_well_e", options.full_well_e},
          {"read_noise_e", options.read_noise * options.full_well_e},
          {"bits", 8}}}}},
      {"photos", photos}};
  WriteJsonFile((tmp / "session.json").string(), session);
  WriteJsonFile((tmp / "truth-lights.json").string(), {{"format", "ibrdf-lights"},
                                                       {"version", 1},
                                                       {"lights", lights},
                                                       {"generator",
                                                        {{"lights", options.lights},
                                                         {"max_light_angle_deg", options.max_light_angle_deg},
                                                         {"point_lights", options.point_lights},
                                                         {"light_distance", options.light_distance},
                                                         {"source_sigma_deg", options.source_sigma_deg},
                                                         {"radius", options.radius},
                                                         {"center", ToJson(options.center)},
                                                         {"focal_px", options.focal_px},
                                                         {"distance", options.distance},
                                                         {"seed", options.seed}}}});
  directory.Commit();
  truth.manifest = (fs::path(out_dir) / "session.json").string();
  return truth;
}

}  // namespace ibrdf
