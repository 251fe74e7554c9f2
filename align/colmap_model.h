// COLMAP sparse models (cameras, images, points3D) in COLMAP's text and binary formats, as COLMAP 3.8
// writes them (colmap/src/base/reconstruction.cc). Supported camera models: SIMPLE_PINHOLE, PINHOLE,
// SIMPLE_RADIAL, RADIAL and OPENCV; any other is a clear error naming the file and the camera. Models
// are also written (tests, and sessions handed to COLMAP).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/rigid3.h"

namespace ibrdf {

struct ColmapImage {
  uint32_t id = 0;
  uint32_t camera_id = 0;
  std::string name;
  Rigid3d camera_from_world;
  std::vector<Eigen::Vector2d> points2d;  // pixel coordinates (COLMAP: pixel centres at +0.5)
  std::vector<int64_t> point3d_ids;       // -1 where the observation has no 3D point

  // The camera centre in world coordinates, -R^T t.
  Eigen::Vector3d Center() const { return camera_from_world.Inverse().translation; }
};

struct ColmapPoint3D {
  uint64_t id = 0;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  uint8_t rgb[3] = {0, 0, 0};
  double error = 0.0;                                // mean reprojection error, pixels
  std::vector<std::pair<uint32_t, uint32_t>> track;  // (image id, index of the 2D point)
};

struct ColmapModel {
  std::map<uint32_t, Camera> cameras;
  std::map<uint32_t, ColmapImage> images;
  std::map<uint64_t, ColmapPoint3D> points;

  // Reads a model folder: cameras.bin, images.bin, points3D.bin if present, else the .txt files.
  static ColmapModel Read(const std::string& directory);
  static ColmapModel ReadBinary(const std::string& directory);
  static ColmapModel ReadText(const std::string& directory);

  // Checks references: every image's camera exists, every track names an existing image and 2D point.
  // Throws Error naming `directory` and the first dangling reference.
  void Validate(const std::string& directory) const;

  // Writes the model in COLMAP 3.8's text (cameras.txt, images.txt, points3D.txt) or binary (.bin)
  // format into `directory`, which must exist; each file appears only when complete. Doubles are
  // written with 17 significant digits, so text round-trips exactly.
  void WriteText(const std::string& directory) const;
  void WriteBinary(const std::string& directory) const;
};

// COLMAP's numeric model ids (colmap/src/base/camera_models.h) and names, for error messages.
const char* ColmapModelNameFromId(int model_id);
// COLMAP's numeric id of a camera model ibrdf supports.
int ColmapModelIdFromName(const std::string& name);

}  // namespace ibrdf
