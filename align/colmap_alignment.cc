#include "align/colmap_alignment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>

#include <Eigen/SVD>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// True when the points (columns) span at least a plane: the second singular value of the centred
// points is not negligible against the first.
bool SpansAPlane(const Eigen::Matrix3Xd& points) {
  if (points.cols() < 3) return false;
  const Eigen::Matrix3Xd centred = points.colwise() - points.rowwise().mean();
  const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3Xd>(centred).singularValues();
  return singular[0] > 0.0 && singular[1] > 1e-6 * singular[0];
}

struct Errors {
  double center_m = 0.0;
  double rotation_deg = 0.0;
};

Errors PoseErrors(const Similarity3d& world_from_colmap, const Rigid3d& colmap_pose, const Rigid3d& target_pose) {
  const Rigid3d metric = world_from_colmap.TransformPose(colmap_pose);
  Errors errors;
  errors.center_m = (metric.Inverse().translation - target_pose.Inverse().translation).norm();
  errors.rotation_deg = metric.rotation.angularDistance(target_pose.rotation) / kDegree;
  return errors;
}

}  // namespace

Similarity3d Similarity3d::Inverse() const {
  Similarity3d inverse;
  inverse.scale = 1.0 / scale;
  inverse.rotation = rotation.conjugate();
  inverse.translation = -(inverse.scale * (inverse.rotation * translation));
  return inverse;
}

Rigid3d Similarity3d::TransformPose(const Rigid3d& camera_from_source) const {
  // p_source = R^T (p_target - t) / s; the camera frame is scaled by s so that it is metric.
  const Eigen::Quaterniond rotation_out = camera_from_source.rotation * rotation.conjugate();
  return Rigid3d(rotation_out, scale * camera_from_source.translation - (rotation_out * translation));
}

Similarity3d Similarity3d::Estimate(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                                    const std::string& where) {
  IBRDF_CHECK(source.cols() == target.cols());
  if (!SpansAPlane(source) || !SpansAPlane(target)) {
    ThrowError(where, "the camera centres are (nearly) collinear or too few (" + std::to_string(source.cols()) +
                          "): a similarity needs at least 3 centres spanning a plane");
  }
  const Eigen::Matrix4d m = Eigen::umeyama(source, target, /*with_scaling=*/true);
  Similarity3d similarity;
  const Eigen::Matrix3d scaled_rotation = m.topLeftCorner<3, 3>();
  similarity.scale = std::cbrt(scaled_rotation.determinant());
  similarity.rotation = Eigen::Quaterniond(scaled_rotation / similarity.scale).normalized();
  similarity.translation = m.topRightCorner<3, 1>();
  return similarity;
}

bool ColmapAlignmentOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(min_images, 3);
  IBRDF_CHECK_OPTION_GT(max_center_error_m, 0.0);
  IBRDF_CHECK_OPTION_GT(max_rotation_error_deg, 0.0);
  IBRDF_CHECK_OPTION_GE(max_triples, 1);
  return true;
}

namespace {

// Each photo's image in the model (result->photos, matched): the exact relative path first, then the
// file name where it is unique in the model.
void MatchPhotos(const ColmapModel& model, const std::vector<std::string>& photo_files,
                 const std::vector<std::optional<Rigid3d>>& target_poses, ColmapAlignment* result) {
  std::map<std::string, int64_t> by_path, by_file_name;
  for (const auto& [id, image] : model.images) {
    by_path[fs::path(image.name).lexically_normal().generic_string()] = id;
    const std::string file_name = fs::path(image.name).filename().string();
    by_file_name[file_name] = by_file_name.count(file_name) ? -2 : int64_t(id);  // -2: ambiguous
  }
  std::map<int64_t, int> claimed;
  for (size_t i = 0; i < photo_files.size(); ++i) {
    ColmapPhotoMatch match;
    match.photo = photo_files[i];
    match.target_pose = target_poses[i];
    const std::string path = fs::path(photo_files[i]).lexically_normal().generic_string();
    int64_t id = -1;
    if (const auto exact = by_path.find(path); exact != by_path.end()) {
      id = exact->second;
    } else if (const auto copy = by_path.find(path + ".png"); copy != by_path.end()) {
      id = copy->second;  // align/colmap_runner's PNG copy of a photo in another format
    } else if (const auto named = by_file_name.find(fs::path(photo_files[i]).filename().string());
               named != by_file_name.end()) {
      id = named->second;  // -2 where ambiguous
    }
    if (id >= 0 && !claimed.count(id)) {
      match.image_id = id;
      claimed[id] = static_cast<int>(i);
      ++result->matched;
    }
    result->photos.push_back(match);
  }
}

// The triples of photos (indices below n) that propose similarities: all of them when there are at
// most max_triples, else max_triples drawn with a fixed seed.
std::vector<std::array<size_t, 3>> CandidateTriples(size_t n, int max_triples) {
  std::vector<std::array<size_t, 3>> triples;
  const double all_triples = double(n) * (n - 1) * (n - 2) / 6.0;
  if (all_triples <= max_triples) {
    for (size_t a = 0; a < n; ++a) {
      for (size_t b = a + 1; b < n; ++b) {
        for (size_t c = b + 1; c < n; ++c) triples.push_back({a, b, c});
      }
    }
  } else {
    std::mt19937_64 rng(42);
    std::uniform_int_distribution<size_t> pick(0, n - 1);
    while (triples.size() < static_cast<size_t>(max_triples)) {
      const size_t a = pick(rng), b = pick(rng), c = pick(rng);
      if (a != b && b != c && a != c) triples.push_back({a, b, c});
    }
  }
  return triples;
}

}  // namespace

ColmapAlignment AlignColmapModel(const ColmapModel& model, const std::vector<std::string>& photo_files,
                                 const std::vector<std::optional<Rigid3d>>& target_poses,
                                 const ColmapAlignmentOptions& options, const std::string& model_directory) {
  std::string why;
  if (!options.Check(&why)) ThrowError("COLMAP alignment options", why);
  IBRDF_CHECK(photo_files.size() == target_poses.size());
  ColmapAlignment result;

  MatchPhotos(model, photo_files, target_poses, &result);
  result.unmatched_images = static_cast<int>(model.images.size()) - result.matched;

  // Photos posed both ways.
  std::vector<size_t> both;
  for (size_t i = 0; i < result.photos.size(); ++i) {
    if (result.photos[i].image_id >= 0 && result.photos[i].target_pose) both.push_back(i);
  }
  result.both = static_cast<int>(both.size());
  if (result.both < options.min_images) {
    ThrowError(model_directory,
               std::to_string(result.matched) + " of the session's " + std::to_string(photo_files.size()) +
                   " photos are in the COLMAP model (matched by file name) and " + std::to_string(result.both) +
                   " of those were posed by the targets; the similarity needs " + std::to_string(options.min_images));
  }
  const auto colmap_pose = [&](size_t i) -> const Rigid3d& {
    return model.images.at(static_cast<uint32_t>(result.photos[i].image_id)).camera_from_world;
  };
  Eigen::Matrix3Xd source(3, both.size()), target(3, both.size());
  for (size_t k = 0; k < both.size(); ++k) {
    source.col(k) = colmap_pose(both[k]).Inverse().translation;
    target.col(k) = result.photos[both[k]].target_pose->Inverse().translation;
  }
  // Inliers of a candidate and their summed squared centre error.
  const auto score = [&](const Similarity3d& candidate, std::vector<bool>* inlier) {
    double squared = 0.0;
    int count = 0;
    inlier->assign(both.size(), false);
    for (size_t k = 0; k < both.size(); ++k) {
      const Errors e = PoseErrors(candidate, colmap_pose(both[k]), *result.photos[both[k]].target_pose);
      if (e.center_m <= options.max_center_error_m && e.rotation_deg <= options.max_rotation_error_deg) {
        (*inlier)[k] = true;
        ++count;
        squared += e.center_m * e.center_m;
      }
    }
    return std::make_pair(count, squared);
  };

  // Consensus over triples: all of them when few enough, else a seeded sample.
  const size_t n = both.size();
  const std::vector<std::array<size_t, 3>> triples = CandidateTriples(n, options.max_triples);
  std::pair<int, double> best_score(0, 0.0);
  std::vector<bool> best_inliers;
  for (const auto& triple : triples) {
    Eigen::Matrix3Xd s(3, 3), t(3, 3);
    for (int k = 0; k < 3; ++k) {
      s.col(k) = source.col(triple[k]);
      t.col(k) = target.col(triple[k]);
    }
    if (!SpansAPlane(s) || !SpansAPlane(t)) continue;
    const Similarity3d candidate = Similarity3d::Estimate(s, t, model_directory);
    std::vector<bool> inlier;
    const auto candidate_score = score(candidate, &inlier);
    if (candidate_score.first > best_score.first ||
        (candidate_score.first == best_score.first && candidate_score.second < best_score.second)) {
      best_score = candidate_score;
      best_inliers = inlier;
    }
  }
  if (best_score.first < options.min_images) {
    ThrowError(
        model_directory,
        "no similarity brings " + std::to_string(options.min_images) + " of the " + std::to_string(n) +
            " photos posed both ways within " + std::to_string(1e3 * options.max_center_error_m) + " mm and " +
            std::to_string(options.max_rotation_error_deg) +
            " degrees of their target-based poses (the centres may be collinear, or the model is not of these photos)");
  }
  // Refit on the inliers until they stop changing.
  Similarity3d similarity;
  std::vector<bool> inliers = best_inliers;
  for (int round = 0; round < 10; ++round) {
    std::vector<size_t> chosen;
    for (size_t k = 0; k < n; ++k) {
      if (inliers[k]) chosen.push_back(k);
    }
    Eigen::Matrix3Xd s(3, chosen.size()), t(3, chosen.size());
    for (size_t k = 0; k < chosen.size(); ++k) {
      s.col(k) = source.col(chosen[k]);
      t.col(k) = target.col(chosen[k]);
    }
    similarity = Similarity3d::Estimate(s, t, model_directory);
    std::vector<bool> next;
    const auto next_score = score(similarity, &next);
    if (next == inliers || next_score.first < options.min_images) break;
    inliers = next;
  }
  result.world_from_colmap = similarity;

  // Residuals and metric poses.
  double center_squared = 0.0, rotation_squared = 0.0;
  for (size_t k = 0; k < n; ++k) {
    ColmapPhotoMatch& match = result.photos[both[k]];
    const Errors e = PoseErrors(similarity, colmap_pose(both[k]), *match.target_pose);
    match.center_error_m = e.center_m;
    match.rotation_error_deg = e.rotation_deg;
    match.inlier = inliers[k];
    if (!inliers[k]) continue;
    ++result.inliers;
    center_squared += e.center_m * e.center_m;
    rotation_squared += e.rotation_deg * e.rotation_deg;
    result.max_center_error_m = std::max(result.max_center_error_m, e.center_m);
  }
  result.rms_center_error_m = std::sqrt(center_squared / result.inliers);
  result.rms_rotation_error_deg = std::sqrt(rotation_squared / result.inliers);
  for (size_t i = 0; i < result.photos.size(); ++i) {
    if (result.photos[i].image_id >= 0) result.photos[i].metric_pose = similarity.TransformPose(colmap_pose(i));
  }
  result.success = true;
  return result;
}

const Camera* SharedColmapCamera(const ColmapModel& model, const ColmapAlignment& alignment) {
  const Camera* shared = nullptr;
  uint32_t shared_id = 0;
  for (const ColmapPhotoMatch& match : alignment.photos) {
    if (match.image_id < 0) continue;
    const uint32_t camera_id = model.images.at(static_cast<uint32_t>(match.image_id)).camera_id;
    if (shared && camera_id != shared_id) return nullptr;
    shared_id = camera_id;
    shared = &model.cameras.at(camera_id);
  }
  return shared;
}

std::string ColmapAlignment::BriefReport() const {
  char buffer[400];
  std::snprintf(
      buffer, sizeof(buffer),
      "colmap: %d photos registered (%d images unmatched), %d posed by the targets too, %d inliers; scale %.6g; "
      "camera centres RMS %.3f mm (max %.3f mm), orientations RMS %.4f deg",
      matched, unmatched_images, both, inliers, world_from_colmap.scale, 1e3 * rms_center_error_m,
      1e3 * max_center_error_m, rms_rotation_error_deg);
  return buffer;
}

nlohmann::json ToJson(const ColmapAlignment& alignment) {
  nlohmann::json photos = nlohmann::json::array();
  for (const ColmapPhotoMatch& match : alignment.photos) {
    nlohmann::json entry = {{"photo", match.photo}, {"registered", match.image_id >= 0}};
    if (match.image_id >= 0) entry["colmap_image_id"] = match.image_id;
    entry["target_posed"] = match.target_pose.has_value();
    if (match.image_id >= 0 && match.target_pose) {
      entry["inlier"] = match.inlier;
      entry["center_error_m"] = match.center_error_m;
      entry["rotation_error_deg"] = match.rotation_error_deg;
    }
    photos.push_back(entry);
  }
  const Similarity3d& s = alignment.world_from_colmap;
  return {{"world_from_colmap",
           {{"scale", s.scale},
            {"rotation", {s.rotation.w(), s.rotation.x(), s.rotation.y(), s.rotation.z()}},
            {"translation", ToJson(s.translation)}}},
          {"matched", alignment.matched},
          {"unmatched_images", alignment.unmatched_images},
          {"posed_both_ways", alignment.both},
          {"inliers", alignment.inliers},
          {"rms_center_error_m", alignment.rms_center_error_m},
          {"max_center_error_m", alignment.max_center_error_m},
          {"rms_rotation_error_deg", alignment.rms_rotation_error_deg},
          {"photos", photos}};
}

Session MergeColmapPoses(const Session& input, const Session& target_aligned, const ColmapModel& model,
                         const ColmapAlignment& alignment, bool keep_camera) {
  IBRDF_CHECK(alignment.photos.size() == input.photos.size())
      << alignment.photos.size() << " matches for " << input.photos.size() << " photos";
  Session merged = target_aligned;
  merged.photos.clear();
  for (size_t i = 0; i < input.photos.size(); ++i) {
    const ColmapPhotoMatch& match = alignment.photos[i];
    PhotoSpec photo = input.photos[i];
    if (match.metric_pose && (match.inlier || !match.target_pose)) {
      photo.camera_from_world = *match.metric_pose;
    } else if (match.target_pose) {
      if (match.metric_pose)
        Log(1, "photo " + photo.file + ": COLMAP's pose disagrees with the targets'; the targets' kept");
      photo.camera_from_world = *match.target_pose;
    } else {
      continue;
    }
    merged.photos.push_back(photo);
  }
  const Camera* camera = SharedColmapCamera(model, alignment);
  if (keep_camera) {
    Log(1, "the calibrated intrinsics are kept (COLMAP's are in its model)");
  } else if (camera && camera->width == input.camera.width && camera->height == input.camera.height) {
    merged.camera = *camera;
  } else {
    Log(1,
        "the session's intrinsics are kept: the registered photos do not share one COLMAP camera of the session's "
        "size");
  }
  return merged;
}

}  // namespace ibrdf
