#include "calibrate/colour_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "calibrate/colour_chart_detector.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/radiometry.h"
#include "core/statistics.h"
#include "radiometry/radiance_image.h"

namespace ibrdf {
namespace {

// The homography taking the chart's patch grid (column, row; patch 1 at (0, 0), patch 24 at (5, 3))
// to the undistorted image plane, from the four corner patches (direct linear transform, h33 = 1).
Eigen::Matrix3d GridHomography(const std::array<Eigen::Vector2d, 4>& plane) {
  const double c = kColorCheckerColumns - 1, r = kColorCheckerRows - 1;
  const std::array<Eigen::Vector2d, 4> grid = {Eigen::Vector2d(0, 0), Eigen::Vector2d(c, 0), Eigen::Vector2d(c, r),
                                               Eigen::Vector2d(0, r)};
  Eigen::Matrix<double, 8, 8> a;
  Eigen::Matrix<double, 8, 1> b;
  for (int k = 0; k < 4; ++k) {
    const double u = grid[k].x(), v = grid[k].y(), x = plane[k].x(), y = plane[k].y();
    a.row(2 * k) << u, v, 1, 0, 0, 0, -u * x, -v * x;
    a.row(2 * k + 1) << 0, 0, 0, u, v, 1, -u * y, -v * y;
    b(2 * k) = x;
    b(2 * k + 1) = y;
  }
  const Eigen::Matrix<double, 8, 1> h = a.fullPivLu().solve(b);
  Eigen::Matrix3d homography;
  homography << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  return homography;
}

Eigen::Vector2d Apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = h * p.homogeneous();
  return q.hnormalized();
}

std::string Percent(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f %%", 100.0 * value);
  return text;
}

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// "cyan: clipped: 3 of 300 pixels; black 2: too dark ..." ("" when every patch is used).
std::string LeftOut(const std::vector<ColourPatch>& patches) {
  std::string left_out;
  for (const ColourPatch& patch : patches) {
    if (!patch.excluded.empty()) left_out += (left_out.empty() ? "" : "; ") + patch.name + ": " + patch.excluded;
  }
  return left_out;
}

}  // namespace

bool ColourChartOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GT(patch_fraction, 0.0);
  IBRDF_CHECK_OPTION_LE(patch_fraction, 0.9);
  IBRDF_CHECK_OPTION_GE(min_patch_signal, 0.0);
  IBRDF_CHECK_OPTION_GE(max_clipped_fraction, 0.0);
  IBRDF_CHECK_OPTION_GE(min_channel_fraction, 0.0);
  IBRDF_CHECK_OPTION_LT(min_channel_fraction, 1.0);
  IBRDF_CHECK_OPTION_LT(max_clipped_fraction, 1.0);
  IBRDF_CHECK_OPTION_GE(min_patch_pixels, 1);
  IBRDF_CHECK_OPTION_GE(min_patches, 3);
  IBRDF_CHECK_OPTION_LE(min_patches, kColorCheckerPatches);
  return true;
}

std::string ColourChartFit::BriefReport() const {
  if (!success) return "colour: not fitted";
  std::string out = "colour: " + std::to_string(kColorCheckerPatches) + " patches located by " + located_by + ", " +
                    std::to_string(used) + " used";
  const std::string left_out = LeftOut(patches);
  if (!left_out.empty()) out += " (left out: " + left_out + ")";
  return out + "; camera RGB -> " + ColourSpaceName(space) + " residual " + Percent(rms_residual) + " RMS, " +
         Percent(max_residual) + " worst";
}

nlohmann::json ColourChartFit::ToJson() const {
  nlohmann::json json = {{"format", "ibrdf-colour"},
                         {"version", 1},
                         {"chart", kColorCheckerClassic24},
                         {"space", ColourSpaceName(space)},
                         {"reference", ColorCheckerReferenceSource()},
                         {"located_by", located_by},
                         {"space_from_camera", MatrixJson(space_from_camera)},
                         {"patches_used", used},
                         {"rms_residual", rms_residual},
                         {"max_residual", max_residual},
                         {"verdicts", VerdictsToJson(verdicts)},
                         {"patches", nlohmann::json::array()}};
  for (const ColourPatch& patch : patches) {
    nlohmann::json p = {{"patch", patch.index + 1},
                        {"name", patch.name},
                        {"center_px", {patch.center.x(), patch.center.y()}},
                        {"pixels", patch.pixels},
                        {"clipped_pixels", patch.clipped},
                        {"camera_rgb", ibrdf::ToJson(patch.camera_rgb)},
                        {"reference", ibrdf::ToJson(patch.reference)}};
    if (patch.excluded.empty()) {
      p["corrected"] = ibrdf::ToJson(patch.corrected);
      p["residual"] = patch.residual;
    } else {
      p["excluded"] = patch.excluded;
    }
    json["patches"].push_back(p);
  }
  return json;
}

std::array<Eigen::Vector2d, kColorCheckerPatches> ColourPatchCenters(const Camera& camera,
                                                                     const std::array<Eigen::Vector2d, 4>& corners) {
  std::array<Eigen::Vector2d, 4> plane;
  for (int k = 0; k < 4; ++k) plane[k] = camera.CamPlaneFromImage(corners[k]);
  const Eigen::Matrix3d plane_from_grid = GridHomography(plane);
  std::array<Eigen::Vector2d, kColorCheckerPatches> centers;
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    const Eigen::Vector2d grid(k % kColorCheckerColumns, k / kColorCheckerColumns);
    centers[k] = camera.ImageFromCamera(Apply(plane_from_grid, grid).homogeneous());
  }
  return centers;
}

ColourChartFit FitColourChart(const Session& session, const std::array<Eigen::Vector2d, 4>& corners,
                              const ColourChartOptions& options, const std::string& located_by) {
  std::string why;
  if (!options.Check(&why)) ThrowError("colour options", why);
  if (!session.colour_chart) ThrowError(session.manifest_path + ": /colour_chart", "the session has no colour chart");
  const ColourChartSpec& chart = *session.colour_chart;
  const Camera& camera = session.camera;
  for (int k = 0; k < 4; ++k) {
    if (!corners[k].allFinite() || corners[k].x() < 0 || corners[k].y() < 0 || corners[k].x() > camera.width ||
        corners[k].y() > camera.height) {
      ThrowError(session.manifest_path + ": /colour_chart/corners/" + std::to_string(k),
                 "the corner patch's centre lies outside the " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " photo");
    }
  }
  // The whole radiometric chain; no signal floor here (a patch is judged on its mean, below).
  const RadianceImage image = RadianceReader(session).Read(chart.photos, -std::numeric_limits<double>::infinity());
  double longest = 0.0;
  for (const PhotoSpec& photo : chart.photos) longest = std::max(longest, photo.exposure_s * photo.gain);

  std::array<Eigen::Vector2d, 4> plane;
  for (int k = 0; k < 4; ++k) plane[k] = camera.CamPlaneFromImage(corners[k]);
  const Eigen::Matrix3d plane_from_grid = GridHomography(plane);
  const Eigen::Matrix3d grid_from_plane = plane_from_grid.inverse();
  const std::array<Eigen::Vector2d, kColorCheckerPatches> centers = ColourPatchCenters(camera, corners);
  const std::array<Eigen::Vector3d, kColorCheckerPatches> reference = ColorCheckerReference(chart.space);

  ColourChartFit fit;
  fit.space = chart.space;
  fit.located_by = located_by;
  const double half = 0.5 * options.patch_fraction;
  for (int k = 0; k < kColorCheckerPatches; ++k) {
    ColourPatch patch;
    patch.index = k;
    patch.name = ColorCheckerPatchNames()[k];
    patch.center = centers[k];
    patch.reference = reference[k];
    const Eigen::Vector2d cell(k % kColorCheckerColumns, k / kColorCheckerColumns);
    // The read-out square's corners in pixels bound the pixels to test.
    Eigen::Vector2d low = Eigen::Vector2d::Constant(1e300), high = Eigen::Vector2d::Constant(-1e300);
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(-half, -half), Eigen::Vector2d(half, -half),
                                     Eigen::Vector2d(half, half), Eigen::Vector2d(-half, half)}) {
      const Eigen::Vector2d pixel = camera.ImageFromCamera(Apply(plane_from_grid, cell + d).homogeneous());
      low = low.cwiseMin(pixel);
      high = high.cwiseMax(pixel);
    }
    if (!(low.x() >= 0 && low.y() >= 0 && high.x() <= camera.width && high.y() <= camera.height)) {
      ThrowError(session.manifest_path + ": /colour_chart",
                 "patch " + std::to_string(k + 1) + " (" + patch.name + ") lies partly outside the photo " +
                     session.AbsolutePath(chart.photos.front().file) + ": check the chart's corner patches");
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int y = int(std::floor(low.y())); y < int(std::ceil(high.y())) && y < camera.height; ++y) {
      for (int x = int(std::floor(low.x())); x < int(std::ceil(high.x())) && x < camera.width; ++x) {
        const Eigen::Vector2d at =
            Apply(grid_from_plane, camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5))) - cell;
        if (std::abs(at.x()) > half || std::abs(at.y()) > half) continue;
        const size_t p = image.Index(x, y);
        ++patch.pixels;
        if (image.flags[p] & (kPixelSaturated | kPixelNonFinite)) {
          ++patch.clipped;
          continue;
        }
        for (int c = 0; c < 3; ++c) sum[c] += image.radiance[3 * p + c];
      }
    }
    const int good = patch.pixels - patch.clipped;
    if (good > 0) patch.camera_rgb = sum / good;
    if (patch.pixels < options.min_patch_pixels) {
      patch.excluded = "too small: " + std::to_string(patch.pixels) + " pixels (at least " +
                       std::to_string(options.min_patch_pixels) + ")";
    } else if (patch.clipped > options.max_clipped_fraction * patch.pixels) {
      patch.excluded = "clipped: " + std::to_string(patch.clipped) + " of " + std::to_string(patch.pixels) + " pixels";
    } else if (patch.camera_rgb.maxCoeff() * longest < options.min_patch_signal) {
      char text[96];
      std::snprintf(text, sizeof(text), "too dark: signal %.4f (at least %.4f)", patch.camera_rgb.maxCoeff() * longest,
                    options.min_patch_signal);
      patch.excluded = text;
    }
    fit.patches.push_back(patch);
  }
  // Black channels, against the brightest usable patch in each channel.
  Eigen::Vector3d brightest = Eigen::Vector3d::Zero();
  for (const ColourPatch& patch : fit.patches) {
    if (patch.excluded.empty()) brightest = brightest.cwiseMax(patch.camera_rgb);
  }
  for (ColourPatch& patch : fit.patches) {
    if (!patch.excluded.empty()) continue;
    for (int c = 0; c < 3; ++c) {
      if (patch.camera_rgb[c] >= options.min_channel_fraction * brightest[c]) continue;
      static const char* const kChannels[3] = {"red", "green", "blue"};
      char text[128];
      std::snprintf(text, sizeof(text), "black channel: camera %s %.2g %% of the brightest patch's (at least %.2g %%)",
                    kChannels[c], 100.0 * patch.camera_rgb[c] / brightest[c],
                    100.0 * options.min_channel_fraction);
      patch.excluded = text;
      break;
    }
  }
  // Least squares: space_from_camera minimizes sum |M c_k - r_k|^2 over the used patches.
  Eigen::MatrixXd cameras(3, kColorCheckerPatches), targets(3, kColorCheckerPatches);
  for (const ColourPatch& patch : fit.patches) {
    if (!patch.excluded.empty()) continue;
    cameras.col(fit.used) = patch.camera_rgb;
    targets.col(fit.used) = patch.reference;
    ++fit.used;
  }
  if (fit.used < options.min_patches) {
    ThrowError(session.manifest_path + ": /colour_chart",
               "only " + std::to_string(fit.used) + " of the chart's patches are usable (at least " +
                   std::to_string(options.min_patches) + " needed; left out: " + LeftOut(fit.patches) + ")" +
                   "; expose the chart so that its white patch is bright but not clipped");
  }
  const Eigen::MatrixXd c = cameras.leftCols(fit.used), t = targets.leftCols(fit.used);
  const Eigen::Matrix3d normal = c * c.transpose();
  if (!(normal.fullPivLu().rank() == 3)) {
    ThrowError(session.manifest_path + ": /colour_chart",
               "the usable patches' camera colours do not span three dimensions (a grey or single-channel photo?)");
  }
  fit.space_from_camera = (t * c.transpose()) * normal.inverse();
  double sum_squares = 0.0;
  for (ColourPatch& patch : fit.patches) {
    patch.corrected = fit.space_from_camera * patch.camera_rgb;
    patch.residual = (patch.corrected - patch.reference).norm() / patch.reference.norm();
    if (!patch.excluded.empty()) continue;
    sum_squares += patch.residual * patch.residual;
    fit.max_residual = std::max(fit.max_residual, patch.residual);
  }
  fit.rms_residual = std::sqrt(sum_squares / fit.used);
  fit.success = true;
  return fit;
}

ColourChartFit LocateAndFitColourChart(const Session& session, const ColourChartOptions& options, bool detect) {
  if (!session.colour_chart) {
    ThrowError(session.manifest_path, "has no colour_chart block (docs/session-format.md): nothing to fit");
  }
  if (session.colour_chart->corners && !detect) {
    return FitColourChart(session, *session.colour_chart->corners, options, "corner patches (session)");
  }
  const ColourChartDetection detection = DetectColorChecker(ColourChartDisplayImage(session));
  if (!detection.found) {
    ThrowError(session.AbsolutePath(session.colour_chart->photos.front().file),
               detection.why +
                   "; give the centres of patches 1, 6, 24 and 19 in colour_chart.corners "
                   "(docs/session-format.md)");
  }
  char cost[64];
  std::snprintf(cost, sizeof(cost), "%.3g", detection.cost);
  Log(1, std::string("OpenCV mcc found a chart (cost ") + cost + "); choosing its orientation by the fit");
  ColourChartFit fit;
  std::string last_error;
  for (const auto& corners : CornerPatchCandidates(detection.box)) {
    try {
      ColourChartFit candidate = FitColourChart(session, corners, options, "OpenCV mcc detector");
      if (!fit.success || candidate.rms_residual < fit.rms_residual) fit = candidate;
    } catch (const Error& error) {
      last_error = error.what();
    }
  }
  if (!fit.success) ThrowError(session.manifest_path, "the detected chart gives no usable fit: " + last_error);
  return fit;
}

Image ColourChartDisplayImage(const Session& session) {
  if (!session.colour_chart) ThrowError(session.manifest_path + ": /colour_chart", "the session has no colour chart");
  const RadianceImage radiance =
      RadianceReader(session).Read(session.colour_chart->photos, -std::numeric_limits<double>::infinity());
  std::vector<float> brightest(size_t(radiance.width) * radiance.height);
  for (size_t p = 0; p < brightest.size(); ++p) {
    brightest[p] = std::max({radiance.radiance[3 * p], radiance.radiance[3 * p + 1], radiance.radiance[3 * p + 2]});
  }
  std::vector<float> sorted = brightest;
  const double level = PercentileInPlace(&sorted, 0.99);
  const double scale = level > 0.0 ? 0.9 / level : 1.0;
  Image display(radiance.width, radiance.height, 3);
  for (size_t p = 0; p < brightest.size(); ++p) {
    for (int c = 0; c < 3; ++c) {
      display.pixels[3 * p + c] =
          static_cast<float>(LinearToSrgb(std::clamp(scale * radiance.radiance[3 * p + c], 0.0, 1.0)));
    }
  }
  return display;
}

std::vector<Verdict> ColourChartVerdicts(const ColourChartFit& fit) {
  std::vector<Verdict> verdicts;
  char text[160];
  Verdict residual;
  residual.check = "colour.fit_residual";
  residual.value = fit.rms_residual;
  std::snprintf(text, sizeof(text), "residual %.2f %% RMS over %d patches (worst %.2f %%)", 100.0 * fit.rms_residual,
                fit.used, 100.0 * fit.max_residual);
  residual.measured = text;
  residual.bound = "warn over 3 %, fail over 10 %";
  residual.level = VerdictAbove(fit.rms_residual, 0.03, 0.10);
  residual.remedy = "check the chart's corner patches (colour_chart.corners) or detect it (--detect); light the chart "
                    "evenly, without glare";
  verdicts.push_back(residual);
  Verdict used;
  used.check = "colour.patches_used";
  used.value = fit.used;
  std::snprintf(text, sizeof(text), "%d of %d patches used", fit.used, kColorCheckerPatches);
  used.measured = text;
  used.bound = "warn under 18";
  used.level = fit.used < 18 ? VerdictLevel::kWarn : VerdictLevel::kOk;
  used.remedy = "expose the chart so that its white patch is bright but not clipped (the left-out patches say why)";
  verdicts.push_back(used);
  return verdicts;
}

void WriteColourStage(const Session& session, const ColourChartFit& fit, const std::string& out_dir, bool overwrite) {
  IBRDF_CHECK(fit.success) << "writing a colour fit that did not run";
  Session corrected = session;
  StoreColourFit(fit, &*corrected.colour_chart);
  Image display = ColourChartDisplayImage(session);
  // Each patch's read-out centre: a small cross, green where used and red where left out.
  for (const ColourPatch& patch : fit.patches) {
    const Eigen::Vector3f mark = patch.excluded.empty() ? Eigen::Vector3f(0, 1, 0) : Eigen::Vector3f(1, 0, 0);
    for (int d = -4; d <= 4; ++d) {
      for (const Eigen::Vector2i& at : {Eigen::Vector2i(int(patch.center.x()) + d, int(patch.center.y())),
                                        Eigen::Vector2i(int(patch.center.x()), int(patch.center.y()) + d)}) {
        if (at.x() < 0 || at.y() < 0 || at.x() >= display.width || at.y() >= display.height) continue;
        for (int c = 0; c < 3; ++c) display.at(at.x(), at.y(), c) = mark[c];
      }
    }
  }
  AtomicDirectory directory(out_dir, overwrite);
  const std::string folder = directory.temporary_path();
  corrected.MarkApplied(SessionStage::kColour);
  corrected.Rebased(out_dir).Save((std::filesystem::path(folder) / "session.json").string());
  WriteJsonFile((std::filesystem::path(folder) / "colour.json").string(), fit.ToJson());
  WriteImage((std::filesystem::path(folder) / "chart.png").string(), display, PixelFormat::kUint8);
  directory.Commit();
}

void StoreColourFit(const ColourChartFit& fit, ColourChartSpec* chart) {
  IBRDF_CHECK(fit.success) << "storing a colour fit that did not run";
  chart->matrix = fit.space_from_camera;
  chart->patches.clear();
  for (const ColourPatch& patch : fit.patches) {
    ColourPatchFit stored;
    stored.name = patch.name;
    stored.excluded = patch.excluded;
    stored.residual = patch.excluded.empty() ? patch.residual : 0.0;
    chart->patches.push_back(stored);
  }
}

}  // namespace ibrdf
