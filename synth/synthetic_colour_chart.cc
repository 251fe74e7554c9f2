#include "synth/synthetic_colour_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <tbb/parallel_for.h>
#include <nlohmann/json.hpp>

#include "core/colour.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/statistics.h"
#include "synth/photo_png.h"
#include "synth/pixel_rays.h"
#include "synth/synthetic_exif.h"
#include "synth/synthetic_radiometry.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The chart's frame: centre, unit axes along its columns (right on the print) and rows (down the
// print), and its front normal.
struct ChartFrame {
  Eigen::Vector3d center, right, down, normal;
  // The world point at patch-grid coordinates (column, row), patch 1 at (0, 0), patch 24 at (5, 3).
  Eigen::Vector3d At(double column, double row, double pitch) const {
    return center +
           pitch * ((column - 0.5 * (kColorCheckerColumns - 1)) * right + (row - 0.5 * (kColorCheckerRows - 1)) * down);
  }
};

// The chart's ideal radiance image in linear sRGB: Lambertian patches of the reference albedo on a
// card of albedo card_albedo (half a pitch of card around the patches); 0 off the card. `on_white`
// gets 1 where a pixel centre sees the white patch (the exposure's reference).
Image RenderChart(const Session& session, const Light& light, const Rigid3d& camera_from_world, const ChartFrame& frame,
                  const SynthColourOptions& colour, int supersample, std::vector<uint8_t>* on_white) {
  const Camera& camera = session.camera;
  const std::array<Eigen::Vector3d, kColorCheckerPatches> albedo = ColorCheckerReference(ColourSpace::kLinearSrgb);
  const double pitch = colour.chart_pitch;
  const double half_columns = 0.5 * kColorCheckerColumns, half_rows = 0.5 * kColorCheckerRows;
  on_white->assign(size_t(camera.width) * camera.height, 0);
  return RenderRays(PixelRays(camera, supersample), camera_from_world,
                    [&](const Eigen::Vector3d& eye, const PixelRay& ray) -> Eigen::Vector3d {
                      double t;
                      if (!RayPlaneHit(eye, ray.direction, frame.center, frame.normal, &t)) {
                        return Eigen::Vector3d::Zero();
                      }
                      const Eigen::Vector3d point = eye + t * ray.direction;
                      // Grid coordinates with the card's centre at 0: patch k's centre at (k % 6 - 2.5, k / 6 - 1.5).
                      const double u = (point - frame.center).dot(frame.right) / pitch;
                      const double v = (point - frame.center).dot(frame.down) / pitch;
                      if (std::abs(u) > half_columns + 0.5 || std::abs(v) > half_rows + 0.5) {
                        return Eigen::Vector3d::Zero();  // off the card
                      }
                      Eigen::Vector3d rho = Eigen::Vector3d::Constant(colour.chart_card_albedo);
                      const double column = std::round(u + half_columns - 0.5), row = std::round(v + half_rows - 0.5);
                      const bool in_grid =
                          column >= 0 && column < kColorCheckerColumns && row >= 0 && row < kColorCheckerRows;
                      const double du = u + half_columns - 0.5 - column, dv = v + half_rows - 0.5 - row;
                      const int patch = in_grid ? int(row) * kColorCheckerColumns + int(column) : -1;
                      if (in_grid && std::abs(du) <= 0.5 * colour.chart_patch_fraction &&
                          std::abs(dv) <= 0.5 * colour.chart_patch_fraction) {
                        rho = albedo[patch];
                        if (patch == 18 && ray.centre) (*on_white)[ray.pixel] = 1;
                      }
                      const Incidence incidence = IncidenceAt(light, point, frame.normal);
                      if (!incidence.lit) return Eigen::Vector3d::Zero();
                      return Eigen::Vector3d(rho.cwiseProduct(incidence.irradiance) / M_PI);
                    });
}

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

}  // namespace

bool SynthColourOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(camera_matrix.allFinite());
  IBRDF_CHECK_OPTION(std::abs(camera_matrix.determinant()) > 1e-6);
  IBRDF_CHECK_OPTION_GT(chart_pitch, 0.0);
  IBRDF_CHECK_OPTION_GT(chart_patch_fraction, 0.0);
  IBRDF_CHECK_OPTION_LE(chart_patch_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(chart_card_albedo, 0.0);
  IBRDF_CHECK_OPTION_LE(chart_card_albedo, 1.0);
  IBRDF_CHECK_OPTION_GT(chart_exposure_scale, 0.0);
  return true;
}

void ApplyCameraMatrix(const Eigen::Matrix3d& camera_matrix, Image* image) {
  if (camera_matrix.isIdentity(0.0) || image->channels < 3) return;
  const Eigen::Matrix3f m = camera_matrix.cast<float>();
  const size_t n = size_t(image->width) * image->height;
  const int channels = image->channels;
  tbb::parallel_for(size_t(0), n, [&](size_t p) {
    float* rgb = &image->pixels[p * channels];
    const Eigen::Vector3f camera = m * Eigen::Map<const Eigen::Vector3f>(rgb);
    for (int c = 0; c < 3; ++c) rgb[c] = camera[c];
  });
}

nlohmann::json WriteSynthColour(const SynthOptions& options, const std::string& directory, Session* session) {
  const SynthColourOptions& colour = options.colour;
  const bool tinted = !colour.camera_matrix.isIdentity(0.0);
  if (!colour.chart && !tinted) return nullptr;
  nlohmann::json truth = {{"camera_matrix", MatrixJson(colour.camera_matrix)},
                          {"camera_matrix_meaning", "camera RGB = camera_matrix * linear sRGB"}};
  if (colour.chart) {
    const PhotoSpec* first = nullptr;
    for (const PhotoSpec& photo : session->photos) {
      if (photo.role == PhotoRole::kMeasurement && photo.camera_from_world) {
        first = &photo;
        break;
      }
    }
    IBRDF_CHECK(first != nullptr);
    const Light& light = session->lights.at(first->light);
    ChartFrame frame;
    frame.center = session->sample.center;
    const Eigen::Vector3d eye = first->camera_from_world->Inverse().translation;
    const Eigen::Vector3d to_light = DirectionToLight(light, frame.center);
    frame.normal = (to_light + (eye - frame.center).normalized()).normalized();
    // Columns along the camera's x axis as seen on the chart, rows down the print (right x down = -normal).
    const Eigen::Vector3d camera_x =
        first->camera_from_world->rotation.toRotationMatrix().transpose() * Eigen::Vector3d::UnitX();
    frame.right = (camera_x - camera_x.dot(frame.normal) * frame.normal).normalized();
    frame.down = frame.right.cross(frame.normal);
    std::vector<uint8_t> on_white;
    Image image =
        RenderChart(*session, light, *first->camera_from_world, frame, colour, options.effects.supersample, &on_white);
    ApplyCameraMatrix(colour.camera_matrix, &image);
    std::vector<float> levels;
    for (size_t p = 0; p < on_white.size(); ++p) {
      if (on_white[p])
        levels.push_back(std::max({image.pixels[3 * p], image.pixels[3 * p + 1], image.pixels[3 * p + 2]}));
    }
    IBRDF_CHECK(!levels.empty()) << "the colour chart's white patch is out of view";
    const double level = PercentileInPlace(&levels, 0.99);
    IBRDF_CHECK(level > 0.0) << "the colour chart is unlit";
    PhotoSpec photo;
    photo.file = std::string("calibration/colour-chart.") + (options.effects.bits == 0 ? "exr" : "png");
    photo.camera_from_world = first->camera_from_world;
    photo.exposure_s = colour.chart_exposure_scale * options.rig.exposure_target / level;
    photo.gain = 1.0;
    photo.light = first->light;
    for (float& v : image.pixels) v = static_cast<float>(v * photo.exposure_s);
    ApplyVignetting(session->camera, options.effects.vignetting, &image);
    const uint64_t clipped = SimulateSensor(options.effects, options.seed, 0xC0C0ull, &image);
    const PixelFormat format = options.effects.bits == 0   ? PixelFormat::kFloat
                               : options.effects.bits <= 8 ? PixelFormat::kUint8
                                                           : PixelFormat::kUint16;
    fs::create_directories(fs::path(directory) / "calibration");
    const PhotoMetadata exif = SyntheticPhotoMetadata(*session, photo, session->photos.size());
    WritePhotoPng((fs::path(directory) / photo.file).string(), image, format, &exif);
    ColourChartSpec chart;
    chart.space = colour.space;
    chart.photos.push_back(photo);
    // The corner patches' centres: 1, 6, 24, 19.
    std::array<Eigen::Vector2d, 4> corners;
    const double pitch = colour.chart_pitch;
    const std::array<Eigen::Vector2d, 4> grid = {Eigen::Vector2d(0, 0), Eigen::Vector2d(5, 0), Eigen::Vector2d(5, 3),
                                                 Eigen::Vector2d(0, 3)};
    nlohmann::json corners_json = nlohmann::json::array();
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p_in_camera = *first->camera_from_world * frame.At(grid[k].x(), grid[k].y(), pitch);
      corners[k] = session->camera.ImageFromCamera(p_in_camera);
      corners_json.push_back({corners[k].x(), corners[k].y()});
    }
    if (colour.chart_corners) chart.corners = corners;
    session->colour_chart = chart;
    nlohmann::json albedos = nlohmann::json::array();
    for (const Eigen::Vector3d& a : ColorCheckerReference(ColourSpace::kLinearSrgb)) albedos.push_back(ToJson(a));
    truth["chart"] = {{"photo", photo.file},
                      {"albedo_linear_srgb", albedos},
                      {"albedo_source", ColorCheckerReferenceSource()},
                      {"corner_patch_centers_px", corners_json},
                      {"pitch_m", pitch},
                      {"clipped_pixels", clipped}};
  }
  for (size_t k = 0; k < session->lights.size(); ++k) {
    Light& light = session->lights[k];
    const Eigen::Vector3d camera_rgb = colour.camera_matrix * light.intensity;
    if (!(camera_rgb.minCoeff() > 0.0)) {
      ThrowError("synth options", "the camera matrix makes light " + std::to_string(k) +
                                      "'s camera-RGB intensity non-positive; use a matrix with positive rows");
    }
    if (light.has_intensity) light.intensity = camera_rgb;
  }
  return truth;
}

}  // namespace ibrdf
