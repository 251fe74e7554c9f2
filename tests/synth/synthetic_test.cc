// The synthetic session generator: reproducible, loadable, and physically placed as in the paper.
#include "synth/synthetic.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/session.h"
#include "scan/ply_io.h"
#include "synth/synthetic_shapes.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(Synth, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(SynthOptions().Check(&why)) << why;
  EXPECT_TRUE(CameraEffects().Check(&why)) << why;
  EXPECT_TRUE(CameraEffects::None().Check(&why)) << why;
  SynthOptions bad;
  bad.rig.camera_distance = 0.01;
  EXPECT_FALSE(bad.Check(&why));
}

TEST(Synth, FixedSeedIsReproducibleAndSeedsDiffer) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.num_photos = 2;
  options.rig.width = 160;
  options.rig.height = 120;
  MakeSession(dir / "a", options, material);
  MakeSession(dir / "b", options, material);
  options.seed = 2;
  MakeSession(dir / "c", options, material);
  for (const char* photo : {"/photos/000.png", "/photos/001.png"}) {
    EXPECT_EQ(ReadBytes(dir / "a" + photo), ReadBytes(dir / "b" + photo));
    EXPECT_NE(ReadBytes(dir / "a" + photo), ReadBytes(dir / "c" + photo));
  }
}

TEST(Synth, SessionLoadsWithPosesOnTheArc) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.num_photos = 5;
  options.rig.width = 160;
  options.rig.height = 120;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.photos.size(), 5u);
  const Eigen::Vector3d to_light = (session.lights[0].position - session.sample.center).normalized();
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const PhotoSpec& photo = session.photos[i];
    ASSERT_TRUE(photo.camera_from_world.has_value());
    EXPECT_GT(photo.exposure_s, 0.0);
    const Eigen::Vector3d center = photo.camera_from_world->Inverse().translation;
    EXPECT_NEAR((center - session.sample.center).norm(), options.rig.camera_distance, 1e-9);
    const double azimuth = std::acos(to_light.dot((center - session.sample.center).normalized())) * 180.0 / M_PI;
    EXPECT_NEAR(azimuth, options.rig.arc_start_deg + i * (options.rig.arc_end_deg - options.rig.arc_start_deg) / 4,
                1e-6);
    // The sample centre projects to the principal point.
    const Eigen::Vector2d pixel = session.camera.ImageFromCamera(*photo.camera_from_world * session.sample.center);
    EXPECT_NEAR(pixel.x(), 80.0, 1e-6);
    EXPECT_NEAR(pixel.y(), 60.0, 1e-6);
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "s/truth.json"));
}

// The dome: one camera pose for every photo, a light per photo at light_distance on the upper
// hemisphere, within [arc_start_deg, arc_end_deg] of the camera, no two alike.
TEST(Synth, DomeHasOnePoseAndALightPerPhoto) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.rig = SynthRig::kDome;
  options.rig.num_photos = 12;
  options.rig.width = 80;
  options.rig.height = 60;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.photos.size(), 12u);
  ASSERT_EQ(session.lights.size(), 12u);
  const Eigen::Vector3d camera = session.photos[0].camera_from_world->Inverse().translation;
  const Eigen::Vector3d to_camera = (camera - session.sample.center).normalized();
  for (size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(session.photos[i].camera_from_world->translation, session.photos[0].camera_from_world->translation);
    EXPECT_EQ(session.photos[i].light, i);
    const Light& light = session.PhotoLight(i);
    const Eigen::Vector3d offset = light.position - session.sample.center;
    EXPECT_NEAR(offset.norm(), options.scene.light_distance, 1e-9);
    EXPECT_GE(offset.z(), options.scene.light_distance * std::sin(5.0 * M_PI / 180.0) - 1e-9);
    const double angle = std::acos(offset.normalized().dot(to_camera)) * 180.0 / M_PI;
    EXPECT_GE(angle, options.rig.arc_start_deg);
    EXPECT_LE(angle, options.rig.arc_end_deg);
    for (size_t j = 0; j < i; ++j) EXPECT_GT((session.lights[j].position - light.position).norm(), 0.05);
  }
}

// The turntable: in the sample's frame camera and light turn together about the vertical, so every
// photo keeps the lab's distances and the angle between them, and the light goes round.
TEST(Synth, TurntablePosesAndLightsTurnTogether) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.rig = SynthRig::kTurntable;
  options.rig.num_photos = 4;
  options.rig.camera_elevation_deg = 20.0;
  options.rig.width = 80;
  options.rig.height = 60;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  ASSERT_EQ(session.lights.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const Eigen::Vector3d camera = session.photos[i].camera_from_world->Inverse().translation - session.sample.center;
    const Eigen::Vector3d light = session.PhotoLight(i).position - session.sample.center;
    EXPECT_NEAR(camera.norm(), options.rig.camera_distance, 1e-9);
    EXPECT_NEAR(light.norm(), options.scene.light_distance, 1e-9);
    EXPECT_NEAR(std::asin(camera.z() / camera.norm()) * 180.0 / M_PI, 20.0, 1e-6);
    // Light azimuth: -90 degrees per stop (the sample turns +90).
    EXPECT_NEAR(std::remainder(std::atan2(light.y(), light.x()) + M_PI / 2 * i, 2 * M_PI), 0.0, 1e-9);
    // Camera azimuth stays turntable_phase_deg from the light's.
    EXPECT_NEAR(std::remainder(std::atan2(camera.y(), camera.x()) - std::atan2(light.y(), light.x()), 2 * M_PI),
                options.rig.turntable_phase_deg * M_PI / 180.0, 1e-9);
  }
}

TEST(Synth, AutoExposurePutsThe99thPercentileAtTheTarget) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.rig.num_photos = 1;
  options.rig.width = 200;
  options.rig.height = 150;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  const Image image = ReadImage(session.PhotoPath(0));
  std::vector<float> lit;
  for (size_t p = 0; p < image.pixels.size(); p += 3) {
    if (image.pixels[p] > 0.0f) lit.push_back(image.pixels[p]);
  }
  std::sort(lit.begin(), lit.end());
  ASSERT_FALSE(lit.empty());
  EXPECT_NEAR(lit[size_t(0.99 * (lit.size() - 1))], options.rig.exposure_target, 0.02);
}

// Supersampling averages n x n rays over the pixel: inside the disc it matches the centre ray of a
// smooth (Lambertian) image closely, and pixels on the silhouette get partial coverage.
TEST(Synth, SupersamplingAveragesOverThePixel) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.effects = CameraEffects::None();
  options.rig.num_photos = 1;
  options.rig.width = 200;
  options.rig.height = 150;
  const Session session = Session::Load(MakeSession(dir / "s", options, material));
  std::vector<uint8_t> mask;
  const Image centre = RenderRadiance(session, 0, material, 1, &mask);
  const Image averaged = RenderRadiance(session, 0, material, 4, nullptr);
  double peak = 0.0;
  for (float v : centre.pixels) peak = std::max(peak, double(v));
  int interior = 0, partial = 0;
  std::vector<double> ratios;
  for (int y = 1; y + 1 < centre.height; ++y) {
    for (int x = 1; x + 1 < centre.width; ++x) {
      const bool all_hit = mask[y * centre.width + x] && mask[y * centre.width + x - 1] &&
                           mask[y * centre.width + x + 1] && mask[(y - 1) * centre.width + x] &&
                           mask[(y + 1) * centre.width + x];
      const double a = centre.at(x, y, 0), b = averaged.at(x, y, 0);
      if (all_hit && a > 0.2 * peak) {
        ++interior;
        ratios.push_back(b / a);
        // Second-order shading change across a (large) pixel: small, largest where the normal turns fast.
        EXPECT_NEAR(b / a, 1.0, 0.02) << x << "," << y;
      }
      if (!mask[y * centre.width + x] && b > 0.0) ++partial;  // centre misses, some sub-rays hit
    }
  }
  EXPECT_GT(interior, 1000);
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.001);
  EXPECT_GT(partial, 10);
}

TEST(Synth, ExistingOutputIsNotReplacedWithoutOverwrite) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  SynthOptions options;
  options.rig.num_photos = 1;
  options.rig.width = 64;
  options.rig.height = 48;
  MakeSession(dir / "s", options, material);
  EXPECT_THROW(WriteSyntheticSession(options, material, "test", dir / "s", /*overwrite=*/false), Error);
  EXPECT_TRUE(std::filesystem::exists(dir / "s/session.json"));
}

// ---------------------------------------------------------------------------------------------------
// Irregular true shapes (synthetic_shapes.h) and their sessions.

std::vector<std::unique_ptr<ImplicitSample>> AllShapes(const Eigen::Vector3d& center) {
  std::vector<std::unique_ptr<ImplicitSample>> shapes;
  shapes.push_back(std::make_unique<SquashSample>(center, SquashParams()));
  shapes.push_back(std::make_unique<PotSample>(center, PotParams()));
  shapes.push_back(std::make_unique<DentedSphereSample>(center, DentParams()));
  return shapes;
}

Eigen::Vector3d RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

TEST(SynthShapes, DefaultParametersAreValid) {
  std::string why;
  EXPECT_TRUE(SquashParams().Check(&why)) << why;
  EXPECT_TRUE(PotParams().Check(&why)) << why;
  EXPECT_TRUE(DentParams().Check(&why)) << why;
  DentParams bad;
  bad.depth = 1.0;
  EXPECT_FALSE(bad.Check(&why));
  EXPECT_THROW(DentedSphereSample(Eigen::Vector3d::Zero(), bad), Error);
  SynthOptions options;
  options.scene.shape = SynthShape::kSquash;
  EXPECT_FALSE(options.Check(&why));  // needs targets
  options.targets.enabled = true;
  EXPECT_TRUE(options.Check(&why)) << why;
}

// The analytic gradient (the normal) against central differences of F, near the surface.
TEST(SynthShapes, NormalsAreTheGradient) {
  std::mt19937_64 rng(5);
  for (const auto& shape : AllShapes(Eigen::Vector3d::Zero())) {
    for (int i = 0; i < 500; ++i) {
      Eigen::Vector3d normal;
      const Eigen::Vector3d p = shape->RadialPoint(RandomUnit(rng), &normal) + 1e-4 * RandomUnit(rng);
      Eigen::Vector3d gradient, numeric;
      shape->Evaluate(p, &gradient);
      const double h = 1e-7;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(k);
        numeric[k] = (shape->Evaluate(p + step, nullptr) - shape->Evaluate(p - step, nullptr)) / (2 * h);
      }
      ASSERT_LT((gradient - numeric).norm(), 1e-5 * gradient.norm())
          << shape->Describe().dump() << " at " << p.transpose();
      ASSERT_LE(gradient.norm(), shape->Lipschitz() * (1.0 + 1e-12));
    }
  }
}

// Random rays: a reported hit lies on the surface (|F| < 1e-12 m), and a march in 20-micrometre steps
// finds no earlier crossing; a miss has no crossing deeper than the stated tolerance anywhere.
TEST(SynthShapes, HitsAreOnTheSurfaceAndFirstAndMissesAreMisses) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Vector3d center(1e4, -2e3, 50.0);  // far from the origin
  for (const auto& shape : AllShapes(center)) {
    const double radius = shape->BoundingRadius();
    int hits = 0, misses = 0;
    for (int i = 0; i < 300; ++i) {
      const Eigen::Vector3d origin = center + 3.0 * radius * RandomUnit(rng);
      const Eigen::Vector3d aim = center + 1.1 * radius * std::cbrt(uniform(rng)) * RandomUnit(rng);
      const Eigen::Vector3d direction = (aim - origin).normalized();
      SurfaceHit hit;
      const bool found = shape->Intersect(origin, direction, &hit);
      const double end = found ? hit.t : 5.0 * radius;
      double lowest = std::numeric_limits<double>::infinity();
      for (double t = 0.0; t < end - 2e-5; t += 2e-5) {
        lowest = std::min(lowest, shape->Evaluate(origin - center + t * direction, nullptr));
      }
      ASSERT_GT(lowest, -shape->Lipschitz() * ImplicitSample::kMinStep) << shape->Describe().dump();
      if (found) {
        ++hits;
        // The hit point is stored in world coordinates 10 km out (a double's step there is 2e-12 m).
        ASSERT_LT(std::abs(shape->Evaluate(hit.point - center, nullptr)), 1e-10);
        ASSERT_NEAR(hit.normal.norm(), 1.0, 1e-12);
        ASSERT_GT(hit.t, 0.0);
      } else {
        ++misses;
      }
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(misses, 10);
  }
}

// Grazing rays along the tangent plane at a convex point: 10 micrometres inside is a hit near the
// point, 10 micrometres outside a miss.
TEST(SynthShapes, ThinGrazingHitsAreFound) {
  std::mt19937_64 rng(11);
  for (const auto& shape : AllShapes(Eigen::Vector3d::Zero())) {
    if (shape->Describe()["shape"] == "dent") continue;  // not convex
    for (int i = 0; i < 100; ++i) {
      Eigen::Vector3d normal;
      const Eigen::Vector3d p = shape->RadialPoint(RandomUnit(rng), &normal);
      const Eigen::Vector3d tangent = normal.cross(RandomUnit(rng)).normalized();
      const Eigen::Vector3d start = p - 3.0 * shape->BoundingRadius() * tangent;
      SurfaceHit hit;
      ASSERT_TRUE(shape->Intersect(start - 1e-5 * normal, tangent, &hit)) << p.transpose();
      EXPECT_FALSE(shape->Intersect(start + 1e-5 * normal, tangent, &hit)) << p.transpose();
    }
  }
}

TEST(SynthShapes, SizesAndRestingPoint) {
  const SquashSample squash(Eigen::Vector3d::Zero(), SquashParams());
  EXPECT_GT(2.0 * squash.BoundingRadius(), 0.08);
  EXPECT_LT(2.0 * squash.BoundingRadius(), 0.11);
  // The lowest point: no surface point below it, and one within a micrometre of it.
  std::mt19937_64 rng(3);
  double lowest = 0.0;
  for (int i = 0; i < 20000; ++i) lowest = std::min(lowest, squash.RadialPoint(RandomUnit(rng), nullptr).z());
  EXPECT_LE(squash.LowestZ(), lowest + 1e-6);
  EXPECT_GT(squash.LowestZ(), lowest - 2e-4);
  const PotSample pot(Eigen::Vector3d::Zero(), PotParams());
  EXPECT_NEAR(pot.RadialPoint(-Eigen::Vector3d::UnitZ(), nullptr).z(), pot.LowestZ(), 1e-12);
  Eigen::Vector3d normal;
  const Eigen::Vector3d side = pot.RadialPoint(Eigen::Vector3d::UnitX(), &normal);  // on the cylinder
  EXPECT_NEAR(side.x(), PotParams().body_radius + PotParams().fillet, 1e-12);
  EXPECT_LT((normal - Eigen::Vector3d::UnitX()).norm(), 1e-12);
}

SynthOptions SmallShapeSession(SynthShape shape) {
  SynthOptions options;
  options.scene.shape = shape;
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = 3;
  options.rig.width = 200;
  options.rig.height = 150;
  options.effects = CameraEffects::None();
  options.scan.scanner.spacing_m = 0.003;
  options.scan.scanner.views_around = 4;
  options.scan.offset_m = 1e4;
  options.scan.truth_mesh_spacing_m = 0.004;
  return options;
}

// The dent shadows itself under the side light (true self-shadows in its photos); the convex pot does
// not.
TEST(SynthShapes, DentCastsAShadowOnItself) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const SynthSummary dent =
      WriteSyntheticSession(SmallShapeSession(SynthShape::kDent), material, "test", dir / "dent", false);
  EXPECT_GT(dent.shadowed_pixels, 30u);
  const SynthSummary pot =
      WriteSyntheticSession(SmallShapeSession(SynthShape::kPot), material, "test", dir / "pot", false);
  EXPECT_EQ(pot.shadowed_pixels, 0u);
}

// A squash session: a mesh sample with range grids in the scanner's frame (10 km out) that lie on the
// true surface once mapped back, the markers as the scanner saw them, and the truth mesh.
TEST(SynthShapes, ShapeSessionHasScansTargetsAndTruth) {
  ScratchDir dir;
  const LambertianBrdf material(Eigen::Vector3d::Constant(0.5));
  const SynthOptions options = SmallShapeSession(SynthShape::kSquash);
  const SynthSummary summary = WriteSyntheticSession(options, material, "test", dir / "s", false);
  EXPECT_EQ(summary.scan_views, 5);
  const Session session = Session::Load(dir / "s");
  ASSERT_EQ(session.sample.kind, SampleSpec::Kind::kMesh);
  EXPECT_EQ(session.sample.mesh_file, "scan/mesh.ply");
  ASSERT_EQ(session.sample.scan_inputs.size(), 5u);
  ASSERT_TRUE(session.targets.has_value());
  ASSERT_EQ(session.sample.scan_targets.size(), session.targets->reference.size());
  const Rigid3d scan_from_world = ScanFromWorld(options.scan);
  for (size_t i = 0; i < session.sample.scan_targets.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d world = scan_from_world.Inverse() * session.sample.scan_targets[i].corners[k];
      EXPECT_LT((world - session.targets->reference[i].corners[k]).norm(), 6 * options.scan.target_noise_m);
    }
  }
  const std::unique_ptr<ImplicitSample> truth = MakeTrueShape(options.scene);
  const Rigid3d world_from_scan = scan_from_world.Inverse();
  size_t points = 0;
  for (const ScanInputSpec& input : session.sample.scan_inputs) {
    const ScanMesh view = ReadPly(ResolvePath(session.directory, input.file));
    ASSERT_FALSE(view.grid.Empty());
    EXPECT_GT(view.points.front().norm(), 9e3);  // scanner coordinates
    for (const Eigen::Vector3d& p : view.points) {
      // Range noise of 0.1 mm along the ray: within 6 sigma of the surface.
      ASSERT_LT(std::abs(truth->Evaluate(world_from_scan * p - options.scene.origin, nullptr)), 6e-4);
    }
    points += view.points.size();
  }
  EXPECT_EQ(points, summary.scan_points);
  const ScanMesh mesh = ReadPly(dir / "s/truth-mesh.ply");
  ASSERT_EQ(mesh.normals.size(), mesh.points.size());
  for (size_t i = 0; i < mesh.points.size(); i += 7) {
    Eigen::Vector3d gradient;
    EXPECT_LT(std::abs(truth->Evaluate(mesh.points[i] - options.scene.origin, &gradient)), 1e-12);
    EXPECT_LT((mesh.normals[i] - gradient.normalized()).norm(), 1e-6);
  }
  const nlohmann::json truth_json = ReadJsonFile(dir / "s/truth.json");
  EXPECT_EQ(truth_json["generator"]["geometry"]["shape"]["shape"], "squash");
  EXPECT_EQ(truth_json["generator"]["sample"], "squash");
}

}  // namespace
}  // namespace ibrdf
