// What every written sample means, recomputed from the session's geometry without the derenderer:
// the ray through the sample's pixel centre, from its photo's camera, meets the true surface (an
// intersection solved here for the sphere; synth's exact implicit squash for the mesh path) at a
// point whose normal, direction to the light and direction to the camera centre give back the sample's
// wi and wo (taken to the world frame), its stored theta_i, theta_e and delta_phi, and the half and
// difference angles the regression uses. Golden byte hashes notice any change of the samples; these
// tests notice a change of their meaning (wi and wo exchanged, another frame, angles of another pair).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/json_reader.h"
#include "core/light.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "synth/synthetic.h"
#include "synth/synthetic_shapes.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

// The angle between two non-zero vectors, radians, accurate near 0 (atan2 rather than acos).
double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Eigen::Vector3d ToVector(const float (&v)[3]) { return Eigen::Vector3d(v[0], v[1], v[2]); }

// The first hit (t > 0) of origin + t direction (unit) on the sphere, or false.
bool HitSphere(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, const Eigen::Vector3d& center,
               double radius, Eigen::Vector3d* point, Eigen::Vector3d* normal) {
  const Eigen::Vector3d m = origin - center;
  const double b = m.dot(direction), c = m.squaredNorm() - radius * radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return false;
  const double t = -b - std::sqrt(discriminant);
  if (t <= 0.0) return false;
  *point = origin + t * direction;
  *normal = (*point - center).normalized();
  return true;
}

// The unit direction from `point` towards the light, from the light's placement alone.
Eigen::Vector3d TowardsLight(const Light& light, const Eigen::Vector3d& point) {
  switch (light.kind) {
    case Light::Kind::kPoint:
      return (light.position - point).normalized();
    case Light::Kind::kDirectional:
      return light.direction.normalized();
  }
  ADD_FAILURE() << "unknown light kind";
  return Eigen::Vector3d::UnitZ();
}

// The worst disagreement over the checked samples, radians, and the sample that showed it.
struct Worst {
  double value = 0.0;
  size_t index = 0;
  void Add(double error, size_t i) {
    if (!(error <= value)) {  // a NaN counts as the worst
      value = std::isnan(error) ? INFINITY : error;
      index = i;
    }
  }
};

struct MeaningErrors {
  size_t checked = 0, missed = 0;  // samples compared; samples whose pixel ray missed the true surface
  Worst wi_world, wo_world;        // wi, wo taken to the world frame against the light and the camera centre
  Worst theta_i, theta_e;          // stored polar angles against the geometry's
  Worst delta_phi;                 // stored azimuth difference, times min(sin theta_i, sin theta_e)
  Worst theta_h, theta_d;          // half/difference angles of the sample's wi, wo against the geometry's

  std::string Brief() const {
    char line[512];
    std::snprintf(line, sizeof(line),
                  "%zu samples (%zu rays missed); worst, degrees: wi %.2e (sample %zu), wo %.2e (%zu), theta_i %.2e, "
                  "theta_e %.2e, delta_phi %.2e, theta_h %.2e, theta_d %.2e",
                  checked, missed, wi_world.value / kDeg, wi_world.index, wo_world.value / kDeg, wo_world.index,
                  theta_i.value / kDeg, theta_e.value / kDeg, delta_phi.value / kDeg, theta_h.value / kDeg,
                  theta_d.value / kDeg);
    return line;
  }
  static constexpr double kDeg = M_PI / 180.0;
};

// Where the pixel ray of `sample` meets the true surface: `hit(origin, direction, point, normal)`.
using TrueHit = std::function<bool(const Eigen::Vector3d&, const Eigen::Vector3d&, Eigen::Vector3d*, Eigen::Vector3d*)>;

// Compares `samples[i]` for every i in `indices` with the geometry of `session` and `hit`.
MeaningErrors CompareWithGeometry(const Session& session, const std::vector<BrdfSample>& samples,
                                  const std::vector<size_t>& indices, const TrueHit& hit) {
  MeaningErrors errors;
  for (const size_t i : indices) {
    const BrdfSample& s = samples[i];
    if (s.image >= session.photos.size()) {
      ADD_FAILURE() << "sample " << i << " names photo " << s.image << " of " << session.photos.size();
      continue;
    }
    const PhotoSpec& photo = session.photos[s.image];
    const Rigid3d world_from_camera = photo.camera_from_world->Inverse();
    const Eigen::Vector2d xy = session.camera.CamPlaneFromImage(Eigen::Vector2d(s.pixel[0] + 0.5, s.pixel[1] + 0.5));
    const Eigen::Vector3d centre = world_from_camera.translation;
    const Eigen::Vector3d direction = (world_from_camera.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
    Eigen::Vector3d point, n;
    if (!hit(centre, direction, &point, &n)) {
      ++errors.missed;
      continue;
    }
    ++errors.checked;
    const Eigen::Vector3d to_light = TowardsLight(session.lights[photo.light], point);
    const Eigen::Vector3d to_camera = (centre - point).normalized();
    const Eigen::Vector3d wi = ToVector(s.wi), wo = ToVector(s.wo);

    // wi and wo back in the world frame: the stored local frame is the one built from the normal.
    const LocalFrame frame = LocalFrame::FromNormal(n);
    errors.wi_world.Add(AngleBetween(frame.FromLocal(wi), to_light), i);
    errors.wo_world.Add(AngleBetween(frame.FromLocal(wo), to_camera), i);

    // The stored angles against the geometry's, in no frame at all: polar angles from the normal, the
    // azimuth difference as the signed angle about n from the light's tangential part to the camera's.
    const double theta_i = AngleBetween(n, to_light), theta_e = AngleBetween(n, to_camera);
    errors.theta_i.Add(std::abs(s.theta_i - theta_i), i);
    errors.theta_e.Add(std::abs(s.theta_e - theta_e), i);
    const Eigen::Vector3d light_t = to_light - to_light.dot(n) * n, camera_t = to_camera - to_camera.dot(n) * n;
    const double delta_phi = std::atan2(n.dot(light_t.cross(camera_t)), light_t.dot(camera_t));
    // Where either direction is near the normal the azimuth is ill-defined: weigh by the smaller sine.
    errors.delta_phi.Add(std::abs(WrapAngle(s.delta_phi - delta_phi)) * std::min(std::sin(theta_i), std::sin(theta_e)),
                         i);

    // The half/difference angles of the stored pair (what the regression bins) against the geometry's.
    HalfDiffAngles stored;
    if (!ToHalfDiff(wi.normalized(), wo.normalized(), &stored)) {
      ADD_FAILURE() << "sample " << i << " has wi = -wo";
      continue;
    }
    const Eigen::Vector3d h = (to_light + to_camera).normalized();
    errors.theta_h.Add(std::abs(stored.theta_h - AngleBetween(n, h)), i);
    errors.theta_d.Add(std::abs(stored.theta_d - AngleBetween(to_light, h)), i);
  }
  return errors;
}

// Every index of `samples`, or `count` of them drawn with a fixed seed when there are more.
std::vector<size_t> Subset(size_t size, size_t count) {
  std::vector<size_t> indices(size);
  for (size_t i = 0; i < size; ++i) indices[i] = i;
  if (size <= count) return indices;
  std::mt19937_64 rng(7);
  std::shuffle(indices.begin(), indices.end(), rng);
  indices.resize(count);
  return indices;
}

void ExpectAllBelow(const MeaningErrors& e, double tolerance_rad) {
  EXPECT_LT(e.wi_world.value, tolerance_rad) << "wi does not point at the light: sample " << e.wi_world.index;
  EXPECT_LT(e.wo_world.value, tolerance_rad) << "wo does not point at the camera centre: sample " << e.wo_world.index;
  EXPECT_LT(e.theta_i.value, tolerance_rad) << "sample " << e.theta_i.index;
  EXPECT_LT(e.theta_e.value, tolerance_rad) << "sample " << e.theta_e.index;
  EXPECT_LT(e.delta_phi.value, tolerance_rad) << "sample " << e.delta_phi.index;
  EXPECT_LT(e.theta_h.value, tolerance_rad) << "sample " << e.theta_h.index;
  EXPECT_LT(e.theta_d.value, tolerance_rad) << "sample " << e.theta_d.index;
}

// The analytic sphere: 4 photos at 400 x 300 pixels, every written sample. The derenderer traces float
// rays (image-plane points in float) and stores float directions: up to 3e-7 rad (1.5e-5 degree)
// apart from this double-precision geometry; 5e-6 rad leaves room for that and is 10^4 times smaller
// than an exchange of wi and wo anywhere off the mirror diagonal.
TEST(SampleMeaning, SphereSamplesPointAtTheLightAndTheCamera) {
  ScratchDir dir;
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.rig.num_photos = 4;
  options.rig.width = 400;
  options.rig.height = 300;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  ASSERT_EQ(session.sample.kind, SampleSpec::Kind::kSphere);
  DerenderToFile(session, DerenderOptions(), dir / "samples.npy");
  const std::vector<BrdfSample> samples = ReadSamples(dir / "samples.npy");
  ASSERT_GT(samples.size(), 20000u);
  const Eigen::Vector3d center = session.sample.center;
  const double radius = session.sample.radius;
  const MeaningErrors errors =
      CompareWithGeometry(session, samples, Subset(samples.size(), samples.size()),
                          [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d, Eigen::Vector3d* p, Eigen::Vector3d* n) {
                            return HitSphere(o, d, center, radius, p, n);
                          });
  std::printf("sphere: %s\n", errors.Brief().c_str());
  EXPECT_EQ(errors.checked, samples.size());
  EXPECT_EQ(errors.missed, 0u);
  ExpectAllBelow(errors, 5e-6);
}

// The mesh path: synth's squash derendered through its true mesh (1 mm facets with exact vertex
// normals), 4 photos at 800 x 600 pixels (the squash is small in frames that show the marker
// platform), against the exact implicit squash at up to 20000 samples. The mesh's interpolated normal
// departs from the exact one between vertices, and its hit point by micrometres: measured up to 0.08
// degree; 0.25 degree bounds that and is still far below an exchange of wi and wo.
TEST(SampleMeaning, SquashMeshSamplesPointAtTheLightAndTheCamera) {
  ScratchDir dir;
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.scene.shape = SynthShape::kSquash;
  options.targets.enabled = true;  // an irregular shape stands on the marker platform
  options.targets.light_photos = 0;
  options.rig.num_photos = 4;
  options.scan.scanner.spacing_m = 0.004;  // the scan is not used: the true mesh is
  options.scan.truth_mesh_spacing_m = 0.001;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  nlohmann::json manifest = ReadJsonFile(MakeSession(dir / "s", options, *material));
  manifest["sample"] = {{"kind", "mesh"}, {"file", "truth-mesh.ply"}, {"visibility", "off"}};
  const std::string path = dir / "s/session-truth.json";
  WriteJsonFile(path, manifest);
  const Session session = Session::Load(path);
  DerenderToFile(session, DerenderOptions(), dir / "samples.npy");
  const std::vector<BrdfSample> samples = ReadSamples(dir / "samples.npy");
  ASSERT_GT(samples.size(), 10000u);
  const std::unique_ptr<ImplicitSample> shape = MakeTrueShape(options.scene);
  ASSERT_TRUE(shape);
  const MeaningErrors errors =
      CompareWithGeometry(session, samples, Subset(samples.size(), 20000),
                          [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d, Eigen::Vector3d* p, Eigen::Vector3d* n) {
                            SurfaceHit hit;
                            if (!shape->Intersect(o, d, &hit)) return false;
                            *p = hit.point;
                            *n = hit.normal;
                            return true;
                          });
  std::printf("squash mesh: %s\n", errors.Brief().c_str());
  EXPECT_EQ(errors.missed, 0u);
  ExpectAllBelow(errors, 0.25 * M_PI / 180.0);
}

}  // namespace
}  // namespace ibrdf
