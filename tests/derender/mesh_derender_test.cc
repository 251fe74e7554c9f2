// The mesh path of the derenderer on synthetic sessions: a UV-sphere mesh against the analytic
// sphere, the same 10 km from the origin, self-shadowing with shadow rays on and off, markers in
// front of the sample, the errors (missing mesh, no normals, a sample no photo sees), and the stage's
// per-photo steps (DerenderSetup) on either geometry.
#include "derender/derenderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <unordered_map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "derender/analytic_sample.h"
#include "radiometry/radiance_image.h"
#include "scan/ply_io.h"
#include "synth/synthetic_scan.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

constexpr double kAlbedo = 0.5;

// Small, noise-free sphere sessions: 200 x 150 pixels, 4 photos.
SynthOptions SmallSphere() {
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 4;
  options.effects = CameraEffects::None();
  return options;
}

Session LambertianSession(const std::string& dir, const SynthOptions& options) {
  const LambertianBrdf material(Eigen::Vector3d::Constant(kAlbedo));
  return Session::Load(MakeSession(dir, options, material));
}

// The session with its sample replaced by a mesh file (relative to the session folder).
Session WithMesh(Session session, const std::string& file, const Sim3d& world_from_mesh = Sim3d(),
                 Visibility visibility = Visibility::kAuto) {
  session.sample = SampleSpec();
  session.sample.kind = SampleSpec::Kind::kMesh;
  session.sample.mesh_file = file;
  session.sample.world_from_mesh = world_from_mesh;
  session.sample.visibility = visibility;
  return session;
}

uint64_t PixelKey(const BrdfSample& s) { return (uint64_t(s.image) << 40) | (uint64_t(s.pixel[1]) << 20) | s.pixel[0]; }

std::unordered_map<uint64_t, const BrdfSample*> ByPixel(const std::vector<BrdfSample>& samples) {
  std::unordered_map<uint64_t, const BrdfSample*> map;
  for (const BrdfSample& s : samples) map[PixelKey(s)] = &s;
  return map;
}

uint64_t Rejected(const DerenderResult& result, const std::string& reason) {
  const auto it = result.summary.rejected.find(reason);
  return it == result.summary.rejected.end() ? 0 : it->second;
}

// Tessellation bound: a UV sphere of 90 rings x 180 segments (2-degree facets) lies within 12 um of
// the sphere, so a ray at theta_e = 80 degrees meets it up to 12 um x tan(80) = 0.07 mm (0.1 degree
// of the sphere) away from the analytic hit; the interpolated normal there moves cos(theta_i) by up
// to tan(80) x 0.1 deg = 1.7 %. Most hits are far from grazing and from facet centres: median 0.05 %.
TEST(MeshDerender, UvSphereMatchesTheAnalyticSphere) {
  ScratchDir dir;
  const Session analytic = LambertianSession(dir / "s", SmallSphere());
  WritePly(dir / "s/sphere.ply", MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 90, 180));
  const Session mesh_session = WithMesh(analytic, "sphere.ply");
  const DerenderResult exact = Derender(analytic, DerenderOptions());
  const DerenderResult mesh = Derender(mesh_session, DerenderOptions());
  EXPECT_EQ(mesh.summary.sample, "mesh");
  ASSERT_GT(exact.samples.size(), 10000u);
  // Counts add up, convex: no shadow rays (auto, from the computed convexity report).
  uint64_t rejected = 0;
  for (const auto& [reason, count] : mesh.summary.rejected) rejected += count;
  EXPECT_EQ(mesh.summary.accepted + rejected, mesh.summary.pixels_examined);
  EXPECT_FALSE(mesh.summary.shadow_rays_on);
  EXPECT_EQ(mesh.summary.shadow_rays, 0u);
  EXPECT_GT(mesh.summary.shadow_tests_skipped, 0u);
  EXPECT_GT(Rejected(mesh, "mixed_pixel"), 0u);  // the limb

  const auto by_pixel = ByPixel(mesh.samples);
  size_t matched = 0;
  std::vector<double> errors;
  for (const BrdfSample& s : exact.samples) {
    const auto it = by_pixel.find(PixelKey(s));
    if (it == by_pixel.end()) continue;
    ++matched;
    errors.push_back(std::abs(it->second->brdf[0] / s.brdf[0] - 1.0));
    ASSERT_TRUE(std::isfinite(it->second->brdf[0]));
  }
  // Nearly every analytic sample has its mesh twin; the few left are at the grazing limits.
  EXPECT_GT(double(matched) / exact.samples.size(), 0.99);
  EXPECT_GT(double(matched) / mesh.samples.size(), 0.99);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], worst = errors.back();
  EXPECT_LT(median, 5e-4);  // measured 1.1e-4
  EXPECT_LT(worst, 0.01);   // measured 5.3e-3
  std::printf("mesh vs analytic sphere: %zu matched of %zu; |f_mesh / f_exact - 1| median %.2e, max %.2e\n", matched,
              exact.samples.size(), median, worst);
}

// The stage's per-photo steps (DerenderSetup::ReadPhoto and DerenderPhoto, what tests and benchmarks
// call) give, photo after photo, the bytes and counts of the whole stage, with the blocks of rows on
// one thread or across threads, for the analytic sphere and for the mesh (mixed pixels, back faces
// and, visibility on, shadow rays included).
TEST(MeshDerender, PerPhotoStepsGiveTheStagesSamples) {
  ScratchDir dir;
  const Session analytic = LambertianSession(dir / "s", SmallSphere());
  WritePly(dir / "s/sphere.ply", MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 90, 180));
  for (const Session& session : {analytic, WithMesh(analytic, "sphere.ply", Sim3d(), Visibility::kOn)}) {
    const DerenderSetup setup(session, DerenderOptions());
    const DerenderResult whole = setup.DerenderAll();
    ASSERT_EQ(setup.NumPhotos(), session.photos.size());
    ASSERT_GT(whole.samples.size(), 10000u);
    for (const bool parallel : {false, true}) {
      std::vector<BrdfSample> samples;
      RejectionCounts rejected;
      uint64_t shadow_rays = 0;
      RadianceWindow image;
      PhotoSamples photo;
      for (size_t i = 0; i < setup.NumPhotos(); ++i) {
        setup.ReadPhoto(i, &image);
        setup.DerenderPhoto(i, image, parallel, &photo);
        for (const std::vector<BrdfSample>& block : photo.blocks) samples.insert(samples.end(), block.begin(), block.end());
        for (const auto& [reason, count] : photo.rejected) rejected[reason] += count;
        shadow_rays += photo.shadow_rays;
      }
      ASSERT_EQ(samples.size(), whole.samples.size()) << session.sample.mesh_file << " parallel " << parallel;
      EXPECT_EQ(std::memcmp(samples.data(), whole.samples.data(), samples.size() * sizeof(BrdfSample)), 0);
      EXPECT_EQ(rejected, whole.summary.rejected);
      EXPECT_EQ(shadow_rays, whole.summary.shadow_rays);
    }
  }
}

// 10 km from the origin (scanner coordinates often are), the mesh placed by world_from_mesh or
// written 10 km out in the file: the same samples as at the origin, within 1e-4 relative.
TEST(MeshDerender, FarFromOriginGivesSameSamples) {
  ScratchDir dir;
  const ScanMesh sphere = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 60, 120);
  const Session near_analytic = LambertianSession(dir / "near", SmallSphere());
  WritePly(dir / "near/sphere.ply", sphere);
  const DerenderResult near_result = Derender(WithMesh(near_analytic, "sphere.ply"), DerenderOptions());
  SynthOptions far_options = SmallSphere();
  far_options.scene.origin = Eigen::Vector3d(1e4, -1e4, 2e3);
  const Session far_analytic = LambertianSession(dir / "far", far_options);
  ScanMesh far_sphere = sphere;
  for (Eigen::Vector3d& p : far_sphere.points) p += far_options.scene.origin;
  WritePly(dir / "far/sphere.ply", sphere);
  WritePly(dir / "far/far-sphere.ply", far_sphere);
  const Sim3d moved(Eigen::Quaterniond::Identity(), far_options.scene.origin, 1.0);
  for (const Session& far : {WithMesh(far_analytic, "sphere.ply", moved), WithMesh(far_analytic, "far-sphere.ply")}) {
    const DerenderResult far_result = Derender(far, DerenderOptions());
    ASSERT_GT(near_result.samples.size(), 10000u);
    EXPECT_NEAR(double(far_result.samples.size()) / near_result.samples.size(), 1.0, 1e-3);
    const auto by_pixel = ByPixel(far_result.samples);
    size_t matched = 0;
    double worst = 0.0;
    for (const BrdfSample& s : near_result.samples) {
      const auto it = by_pixel.find(PixelKey(s));
      if (it == by_pixel.end()) continue;
      ++matched;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(it->second->brdf[c]) / s.brdf[c] - 1.0));
      ASSERT_NEAR(it->second->theta_i, s.theta_i, 1e-4);
      ASSERT_NEAR(it->second->theta_e, s.theta_e, 1e-4);
    }
    EXPECT_GT(double(matched) / near_result.samples.size(), 0.999);
    EXPECT_LT(worst, 1e-4);
  }
}

// A Lambertian scene with a true self-shadow: the 4 cm sphere and a 1.2 cm ball between it and the
// light, rendered here exactly (pixel centres, analytic spheres, analytic shadow test). Shadowed
// points get a small indirect term (a stand-in for light bounced off the ball), so their pixels are
// above the signal floor and look like measurements: a derenderer without shadow rays takes them as
// samples of a far too bright BRDF.
struct ShadowScene {
  Session session;
  uint64_t shadowed_pixels = 0;
};

ShadowScene RenderShadowScene(const ScratchDir& dir) {
  ShadowScene scene;
  Session session = LambertianSession(dir / "s", SmallSphere());
  const SphereSample sphere(Eigen::Vector3d::Zero(), 0.04);
  const Eigen::Vector3d ball_center(0.07, 0.0, 0.025);
  const SphereSample ball(ball_center, 0.012);
  const Light& light = session.lights[0];
  const double indirect = 0.15 * kAlbedo / M_PI * light.intensity[0] / light.position.squaredNorm();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const Rigid3d world_from_camera = session.photos[i].camera_from_world->Inverse();
    Image image(session.camera.width, session.camera.height, 3);
    double brightest = 0.0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const Eigen::Vector2d xy = session.camera.CamPlaneFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
        const Eigen::Vector3d direction =
            (world_from_camera.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
        SurfaceHit on_sphere, on_ball;
        const bool a = sphere.Intersect(world_from_camera.translation, direction, &on_sphere);
        const bool b = ball.Intersect(world_from_camera.translation, direction, &on_ball);
        if (!a && !b) continue;
        const SurfaceHit& hit = (a && (!b || on_sphere.t < on_ball.t)) ? on_sphere : on_ball;
        const Incidence incidence = IncidenceAt(light, hit.point, hit.normal);
        if (!incidence.lit) continue;
        SurfaceHit blocker;
        const bool shadowed =
            (&hit == &on_sphere) && ball.Intersect(hit.point, incidence.wi, &blocker) && blocker.t < incidence.distance;
        scene.shadowed_pixels += shadowed;
        for (int c = 0; c < 3; ++c) {
          const double radiance = shadowed ? indirect : kAlbedo / M_PI * incidence.irradiance[c];
          image.at(x, y, c) = float(radiance);
          brightest = std::max(brightest, radiance);
        }
      }
    }
    // Exposure: the brightest pixel at 0.8 of full scale.
    const double exposure = 0.8 / brightest;
    for (float& v : image.pixels) v = float(v * exposure);
    session.photos[i].exposure_s = exposure;
    session.photos[i].gain = 1.0;
    WriteImage(session.PhotoPath(i), image, PixelFormat::kFloat);
  }
  // The mesh: both spheres, UV-tessellated, exact normals.
  ScanMesh mesh = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 90, 180);
  const ScanMesh small = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.012), 40, 80);
  const int offset = int(mesh.points.size());
  for (size_t k = 0; k < small.points.size(); ++k) {
    mesh.points.push_back(small.points[k] + ball_center);
    mesh.normals.push_back(small.normals[k]);
  }
  for (const Eigen::Vector3i& f : small.faces) mesh.faces.push_back(f + Eigen::Vector3i::Constant(offset));
  WritePly(dir / "s/scene.ply", mesh);
  scene.session = WithMesh(session, "scene.ply");
  return scene;
}

size_t CountWrong(const std::vector<BrdfSample>& samples, double bound) {
  size_t wrong = 0;
  for (const BrdfSample& s : samples) wrong += std::abs(s.brdf[0] * M_PI / kAlbedo - 1.0) > bound;
  return wrong;
}

TEST(MeshDerender, ShadowRaysRejectWhatVisibilityOffAcceptsWrongly) {
  ScratchDir dir;
  ShadowScene scene = RenderShadowScene(dir);
  ASSERT_GT(scene.shadowed_pixels, 100u);
  DerenderOptions off, on;
  off.visibility = Visibility::kOff;
  on.visibility = Visibility::kOn;
  const DerenderResult without = Derender(scene.session, off);
  const DerenderResult with = Derender(scene.session, on);
  // Without shadow rays the indirectly lit shadow passes as samples that are off by far more than
  // any tessellation error; with them, it is rejected and what is left matches albedo / pi.
  const size_t wrong_without = CountWrong(without.samples, 0.05);
  EXPECT_GT(wrong_without, 100u);
  EXPECT_EQ(Rejected(without, "shadowed"), 0u);
  EXPECT_EQ(without.summary.shadow_rays, 0u);
  EXPECT_EQ(CountWrong(with.samples, 0.05), 0u);
  EXPECT_GT(Rejected(with, "shadowed"), wrong_without / 2);
  EXPECT_GT(Rejected(with, "shadow_edge"), 0u);
  EXPECT_TRUE(with.summary.shadow_rays_on);
  EXPECT_GT(with.summary.shadow_rays, 0u);
  // Auto: the two spheres are far from convex, so the computed convexity report turns shadow rays on.
  const DerenderResult automatic = Derender(scene.session, DerenderOptions());
  EXPECT_TRUE(automatic.summary.shadow_rays_on) << automatic.summary.visibility_reason;
  EXPECT_EQ(automatic.samples.size(), with.samples.size());
  // The session's key does the same as the option.
  Session keyed = scene.session;
  keyed.sample.visibility = Visibility::kOff;
  EXPECT_EQ(Derender(keyed, DerenderOptions()).samples.size(), without.samples.size());
  std::printf(
      "shadow scene: %llu shadowed pixels; visibility off: %zu samples, %zu wrong by > 5 %%; on: %zu samples, "
      "shadowed %llu, shadow_edge %llu\n",
      (unsigned long long)scene.shadowed_pixels, without.samples.size(), wrong_without, with.samples.size(),
      (unsigned long long)Rejected(with, "shadowed"), (unsigned long long)Rejected(with, "shadow_edge"));
}

// The scan stage's convexity verdict (<mesh>.json) is reused only when it describes the mesh at hand:
// its mesh name and point and face counts match, and the mesh is not newer than it. A sidecar that
// says "not convex" for the convex UV sphere shows which verdict was taken.
TEST(MeshDerender, ScanSidecarIsReusedOnlyForTheSameMesh) {
  ScratchDir dir;
  const Session analytic = LambertianSession(dir / "s", SmallSphere());
  const ScanMesh sphere = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 45, 90);
  WritePly(dir / "s/sphere.ply", sphere);
  const Session session = WithMesh(analytic, "sphere.ply");
  auto write_sidecar = [&](const std::string& mesh, size_t faces) {
    const nlohmann::json sidecar = {{"mesh", mesh},
                                    {"points", sphere.points.size()},
                                    {"faces", faces},
                                    {"convexity", {{"needs_shadow_rays", true}}}};
    std::ofstream(dir / "s/sphere.ply.json") << sidecar.dump();
  };
  write_sidecar("sphere.ply", sphere.faces.size());
  DerenderResult result = Derender(session, DerenderOptions());
  EXPECT_TRUE(result.summary.shadow_rays_on) << result.summary.visibility_reason;
  EXPECT_NE(result.summary.visibility_reason.find("the scan's convexity report"), std::string::npos)
      << result.summary.visibility_reason;
  for (const auto& [mesh, faces] : {std::pair<std::string, size_t>("sphere.ply", sphere.faces.size() + 1),
                                    std::pair<std::string, size_t>("other.ply", sphere.faces.size())}) {
    write_sidecar(mesh, faces);
    result = Derender(session, DerenderOptions());
    EXPECT_FALSE(result.summary.shadow_rays_on) << result.summary.visibility_reason;
    EXPECT_NE(result.summary.visibility_reason.find("is stale"), std::string::npos) << result.summary.visibility_reason;
  }
}

TEST(MeshDerender, ReferenceMarkerInFrontOfTheSampleIsMasked) {
  ScratchDir dir;
  const Session analytic = LambertianSession(dir / "s", SmallSphere());
  WritePly(dir / "s/sphere.ply", MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 60, 120));
  Session session = WithMesh(analytic, "sphere.ply");
  // A 2 cm marker a third of the way from the sphere to the first camera, facing it.
  const Eigen::Vector3d camera = session.photos[0].camera_from_world->Inverse().translation;
  const Eigen::Vector3d center = camera / 3.0, axis = camera.normalized();
  const Eigen::Vector3d u = axis.unitOrthogonal() * 0.01, v = axis.cross(u);
  TargetsSpec targets;
  targets.dictionary = "DICT_4X4_50";
  TargetSpec marker;
  marker.id = 0;
  marker.corners = {center - u - v, center + u - v, center + u + v, center - u + v};
  targets.reference.push_back(marker);
  session.targets = targets;
  const DerenderResult plain = Derender(WithMesh(analytic, "sphere.ply"), DerenderOptions());
  const DerenderResult masked = Derender(session, DerenderOptions());
  const uint64_t occluded = Rejected(masked, "occluded_by_target");
  EXPECT_GT(occluded, 100u);
  EXPECT_LT(masked.samples.size(), plain.samples.size());
  EXPECT_LE(plain.samples.size() - masked.samples.size(), occluded);
}

TEST(MeshDerender, MissingCorruptOrNormalFreeMeshIsAClearError) {
  ScratchDir dir;
  const Session analytic = LambertianSession(dir / "s", SmallSphere());
  auto expect_error = [&](const Session& session, const std::string& what) {
    try {
      Derender(session, DerenderOptions());
      FAIL() << "expected an error containing \"" << what << "\"";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error(WithMesh(analytic, "nothing.ply"), "does not exist");
  ScanMesh no_normals = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 20, 40);
  no_normals.normals.clear();
  WritePly(dir / "s/bare.ply", no_normals);
  expect_error(WithMesh(analytic, "bare.ply"), "no per-point normals");
  {
    std::ofstream out(dir / "s/broken.ply");
    out << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  }
  expect_error(WithMesh(analytic, "broken.ply"), "broken.ply");
  // A vertex at 3e38 m: the mesh is named, not "no photo sees the sample" against session.json.
  ScanMesh far = MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 20, 40);
  far.points[7].x() = 3e38;
  WritePly(dir / "s/far.ply", far);
  expect_error(WithMesh(analytic, "far.ply"), "far.ply");
  expect_error(WithMesh(analytic, "far.ply"), "vertex 7 lies at");
  // Ten metres above the scene: no photo sees it.
  WritePly(dir / "s/sphere.ply", MakeUvEllipsoid(Eigen::Vector3d::Constant(0.04), 20, 40));
  const Sim3d away(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 10), 1.0);
  expect_error(WithMesh(analytic, "sphere.ply", away), "no photo sees the sample");
  // The analytic path refuses nothing new: a mesh session through DerenderAnalytic is an error.
  EXPECT_THROW(DerenderAnalytic(WithMesh(analytic, "sphere.ply"), DerenderOptions()), Error);
}

// The sample's mesh keys survive Save and Load; bad values are errors naming the field.
TEST(MeshDerender, SessionMeshKeysRoundTrip) {
  ScratchDir dir;
  Session session = LambertianSession(dir / "s", SmallSphere());
  session = WithMesh(session, "scan/mesh.ply",
                     Sim3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ())),
                           Eigen::Vector3d(1e4, 2.0, -3.0), 0.001),
                     Visibility::kOn);
  session.sample.scan_inputs = {{"scan/view-0.ply", std::nullopt},
                                {"scan/view-1.ply", Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1))}};
  ScanTargetSpec target;
  target.id = 3;
  target.corners = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 0),
                    Eigen::Vector3d(0, 1, 0)};
  session.sample.scan_targets = {target};
  session.Save(dir / "s/session.json");
  const Session back = Session::Load(dir / "s");  // the mesh file need not exist yet
  EXPECT_EQ(back.sample.kind, SampleSpec::Kind::kMesh);
  EXPECT_EQ(back.sample.mesh_file, "scan/mesh.ply");
  EXPECT_EQ(back.sample.visibility, Visibility::kOn);
  EXPECT_NEAR(back.sample.world_from_mesh.scale, 0.001, 1e-15);
  EXPECT_NEAR((back.sample.world_from_mesh.translation - Eigen::Vector3d(1e4, 2.0, -3.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(back.sample.world_from_mesh.rotation.angularDistance(session.sample.world_from_mesh.rotation), 0.0,
              1e-12);
  ASSERT_EQ(back.sample.scan_inputs.size(), 2u);
  EXPECT_FALSE(back.sample.scan_inputs[0].world_from_scan.has_value());
  ASSERT_TRUE(back.sample.scan_inputs[1].world_from_scan.has_value());
  ASSERT_EQ(back.sample.scan_targets.size(), 1u);
  EXPECT_EQ(back.sample.scan_targets[0].id, 3);
  EXPECT_EQ(back.sample.scan_targets[0].corners[2], Eigen::Vector3d(1, 1, 0));

  auto expect_load_error = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& what) {
    nlohmann::json json = session.ToJson();
    edit(json);
    WriteJsonFile(dir / "s/session.json", json);
    try {
      Session::Load(dir / "s");
      FAIL() << "expected an error containing \"" << what << "\"";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_load_error([](nlohmann::json& j) { j["sample"]["visibility"] = "sometimes"; }, "/sample/visibility");
  expect_load_error([](nlohmann::json& j) { j["sample"]["world_from_mesh"]["scale"] = -1.0; },
                    "/sample/world_from_mesh/scale");
  expect_load_error([](nlohmann::json& j) { j["sample"]["world_from_mesh"]["shear"] = 1.0; }, "shear");
  expect_load_error([](nlohmann::json& j) { j["sample"]["scan_inputs"][0] = 5; }, "/sample/scan_inputs/0");
  expect_load_error([](nlohmann::json& j) { j["sample"]["scan_targets"][0]["corners"].erase(0); },
                    "/sample/scan_targets/0/corners");
  expect_load_error([](nlohmann::json& j) { j["sample"]["radius"] = 1.0; }, "radius");
}

}  // namespace
}  // namespace ibrdf
