#include "report/light_photos.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/light_json.h"
#include "core/math.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "core/statistics.h"
#include "radiometry/linear_image.h"
#include "report/acquisition_thumbnails.h"
#include "report/report_png.h"
#include "report/tone_map.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The photo's samples' box (with a margin), linearized and shrunk by an integer box filter to at most
// `size` pixels on a side, tone-mapped.
Image Thumbnail(const Session& session, uint32_t index, const PhotoStats& stats, int size) {
  Image photo = ReadImage(session.PhotoPath(index));
  LinearizeImage(session, index, &photo, /*divide_by_exposure=*/true);
  const int pad = std::max(4, (stats.x1 - stats.x0) / 8);
  const int x0 = std::max(0, stats.x0 - pad), y0 = std::max(0, stats.y0 - pad);
  const int x1 = std::min(photo.width - 1, stats.x1 + pad), y1 = std::min(photo.height - 1, stats.y1 + pad);
  return ToneMap(ShrinkRegion(photo, PixelBox{x0, y0, x1, y1}, size), nullptr);
}

}  // namespace

nlohmann::json WriteLightPhotos(const std::string& samples_path, const std::map<uint32_t, PhotoStats>& photos,
                                const std::string& tmp_dir, int thumbnail_size) {
  const std::string sidecar = SidecarPath(samples_path);
  if (!fs::exists(sidecar)) return nullptr;
  Session session;
  try {
    session = Session::Load(ReadJsonFile(sidecar).at("session").get<std::string>());
  } catch (const std::exception&) {
    return nullptr;  // the photo note of the report says why the session cannot be read
  }
  if (session.lights.size() < 2) return nullptr;
  nlohmann::json lights = nlohmann::json::array();
  fs::create_directories(fs::path(tmp_dir) / "lights");
  for (size_t k = 0; k < session.lights.size(); ++k) {
    const Light& light = session.lights[k];
    nlohmann::json entry = LightJson(light);
    entry["id"] = light.id;
    entry.erase("intensity");
    int photo_count = 0;
    uint64_t samples = 0;
    int best = -1;
    std::vector<double> phases;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      if (session.photos[i].role != PhotoRole::kMeasurement || session.photos[i].light != k) continue;
      ++photo_count;
      const auto it = photos.find(static_cast<uint32_t>(i));
      if (it == photos.end()) continue;
      samples += it->second.count;
      for (float phase : it->second.phase) phases.push_back(phase);
      if (best < 0 || it->second.count > photos.at(static_cast<uint32_t>(best)).count) best = static_cast<int>(i);
    }
    entry["photos"] = photo_count;
    entry["samples"] = samples;
    entry["phase_deg"] = phases.empty() ? nlohmann::json(nullptr) : nlohmann::json(Median(phases) / kDegree);
    entry["photo"] = best;
    entry["file"] = "";
    if (best >= 0) {
      char name[32];
      std::snprintf(name, sizeof(name), "lights/%03zu.png", k);
      try {
        WriteReportPng(
            (fs::path(tmp_dir) / name).string(),
            Thumbnail(session, static_cast<uint32_t>(best), photos.at(static_cast<uint32_t>(best)), thumbnail_size));
        entry["file"] = name;
      } catch (const Error& e) {
        entry["note"] = e.what();
      }
    }
    lights.push_back(entry);
  }
  return lights;
}

}  // namespace ibrdf
