#include "spatial/surface_points.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/kind.h"
#include "derender/analytic_sample.h"
#include "derender/mesh_sample.h"
#include "scan/mesh_file.h"

namespace ibrdf {
namespace {

std::unique_ptr<SampleSurface> SurfaceOf(const Session& session) {
  switch (session.sample.kind) {
    case SampleSpec::Kind::kSphere:
    case SampleSpec::Kind::kCylinder:
      return AnalyticSample::Create(session.sample);
    case SampleSpec::Kind::kMesh: {
      const std::string file = ResolvePath(session.directory, session.sample.mesh_file);
      if (!std::filesystem::is_regular_file(file)) {
        ThrowError(session.manifest_path + ": /sample/file", "the mesh " + file + " does not exist");
      }
      return std::make_unique<MeshSample>(ReadTriangleMeshFile(file), session.sample.world_from_mesh, file);
    }
  }
  UnhandledKind("SampleSpec::Kind", int(session.sample.kind));
}

}  // namespace

SurfaceLocator::SurfaceLocator(const Session& session) : camera_(session.camera), surface_(SurfaceOf(session)) {
  poses_.resize(session.photos.size());
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const std::optional<Rigid3d>& camera_from_world = session.photos[i].camera_from_world;
    if (!camera_from_world) continue;
    const Rigid3d world_from_camera = camera_from_world->Inverse();
    poses_[i] = Pose{world_from_camera.rotation.toRotationMatrix(), world_from_camera.translation};
  }
}

SurfaceLocator::~SurfaceLocator() = default;

SurfaceLocator::Outcome SurfaceLocator::Locate(const BrdfSample& sample, Eigen::Vector3d* point) const {
  if (sample.image >= poses_.size() || !poses_[sample.image]) return Outcome::kNoPose;
  const Pose& pose = *poses_[sample.image];
  const Eigen::Vector2d plane = camera_.CamPlaneFromImage(Eigen::Vector2d(sample.pixel[0] + 0.5, sample.pixel[1] + 0.5));
  const Eigen::Vector3d direction = (pose.world_from_camera * Eigen::Vector3d(plane.x(), plane.y(), 1.0)).normalized();
  SurfaceHit hit;
  if (!surface_->Intersect(pose.centre, direction, &hit)) return Outcome::kMissed;
  const double theta_e = std::acos(std::clamp(-direction.dot(hit.normal), -1.0, 1.0));
  if (!(std::abs(theta_e - double(sample.theta_e)) <= kMaxThetaEError)) return Outcome::kMismatch;
  *point = hit.point;
  return Outcome::kFound;
}

Eigen::Vector3d SurfaceLocator::BoundingCenter() const { return surface_->BoundingCenter(); }
double SurfaceLocator::BoundingRadius() const { return surface_->BoundingRadius(); }

std::string SessionOfSamples(const std::string& samples_path, const std::string& given) {
  if (!given.empty()) return given;
  const nlohmann::json sidecar = ReadJsonFile(SidecarPath(samples_path));
  if (!sidecar.contains("session") || !sidecar["session"].is_string()) {
    ThrowError(SidecarPath(samples_path), "names no session: pass --session");
  }
  return sidecar["session"].get<std::string>();
}

}  // namespace ibrdf
