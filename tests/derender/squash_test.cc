// End to end through the stage libraries on irregular synthetic samples: synth a squash with a
// simulated range scan 10 km out -> scan -> align (camera poses, light, and the mesh's registration by
// the markers the scanner saw) -> derender on the scanned mesh -> samples against the true BRDF; the
// same on the true geometry; and a dented sphere's self-shadows with visibility off and on.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "align/align_stage.h"
#include "core/brdf_model.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/truth_comparison.h"
#include "scan/scan_pipeline.h"
#include "synth/synthetic.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

// A small session: 640x480 (markers of 28 mm need about 30 pixels to pose a photo), 4 measurement
// photos, no light-marker photos (the light stays as given), noise-free camera,
// a coarse scan (1.5 mm spacing); as `ibrdf synth --shape SHAPE --effects none --width 640 --height 480
// --photos 4 --light-photos 0 --scan-spacing-m 0.0015 --truth-mesh-spacing-m 0.0015 --scan-offset-m X
// [--fill-light F]` makes it.
void Synth(const std::string& shape, const std::string& out, double scan_offset_m, double fill_light = 0.0) {
  SynthOptions options;
  options.scene.shape = SynthShapeFromName(shape);
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.targets.light_photos = 0;
  options.effects = CameraEffects::None();
  options.rig.width = 640;
  options.rig.height = 480;
  options.rig.num_photos = 4;
  options.scan.scanner.spacing_m = 0.0015;
  options.scan.truth_mesh_spacing_m = 0.0015;
  options.scan.offset_m = scan_offset_m;
  options.scene.fill_light = fill_light;
  const std::string material = testing::MaterialPath("bluepaint");
  ASSERT_TRUE(WriteSyntheticSession(options, *LoadMaterial(material), material, out, false).success);
}

// The scan stage on the session's range grids into its sample's mesh file (as `ibrdf scan` does).
void ScanSession(const std::string& dir) {
  const Session session = Session::Load(dir);
  const ScanOptions options;
  WriteScanOutputs(ResolvePath(session.directory, session.sample.mesh_file), RunScan(InputsFromSession(session), options),
                   options);
}

void Align(const std::string& session, const std::string& out) {
  AlignSessionToFolder(Session::Load(session), AlignStageOptions(), out);
}

void DerenderSession(const std::string& session, const std::string& out) {
  DerenderToFile(Session::Load(session), DerenderOptions(), out);
}

// A copy of a session's manifest in its own folder whose sample is the true geometry (world frame).
std::string TruthMeshSession(const std::string& dir, const std::string& visibility) {
  nlohmann::json manifest = ReadJsonFile(dir + "/session.json");
  manifest["sample"] = {{"kind", "mesh"}, {"file", "truth-mesh.ply"}, {"visibility", visibility}};
  const std::string path = dir + "/session-truth-" + visibility + ".json";
  WriteJsonFile(path, manifest);
  return path;
}

TruthComparison Compare(const std::string& samples, const std::string& truth_json) {
  return CompareWithTruth(ReadSamples(samples), *LoadTruthMaterial(truth_json));
}

TEST(Squash, ScanAlignDerenderMatchesTheTruth) {
  SetVerbosity(0);
  ScratchDir dir;
  const std::string s = dir / "s";
  ASSERT_NO_FATAL_FAILURE(Synth("squash", s, 1e4));
  ScanSession(s);
  Align(s, dir / "aligned");
  const nlohmann::json alignment = ReadJsonFile(dir / "aligned/alignment.json");
  ASSERT_TRUE(alignment.contains("mesh_registration")) << alignment.dump();
  EXPECT_EQ(alignment["mesh_registration"]["used_markers"], 12);
  EXPECT_LT(alignment["mesh_registration"]["rms_m"].get<double>(), 2e-4);
  DerenderSession(dir / "aligned", dir / "scanned.npy");
  const TruthComparison scanned = Compare(dir / "scanned.npy", s + "/truth.json");
  DerenderSession(TruthMeshSession(s, "auto"), dir / "true.npy");
  const TruthComparison truth = Compare(dir / "true.npy", s + "/truth.json");
  std::cout << "scanned mesh: " << scanned.BriefReport() << "\ntrue mesh:    " << truth.BriefReport() << "\n";
  EXPECT_GT(scanned.overall.count, 8000u);
  EXPECT_LT(scanned.overall.median.maxCoeff(), 0.03);
  EXPECT_LT(truth.overall.median.maxCoeff(), 0.03);

  // The same measurement with the scanner's frame at the world's origin: the same samples.
  const std::string near = dir / "near";
  ASSERT_NO_FATAL_FAILURE(Synth("squash", near, 0.0));
  ScanSession(near);
  Align(near, dir / "near-aligned");
  DerenderSession(dir / "near-aligned", dir / "near.npy");
  const std::vector<BrdfSample> far_samples = ReadSamples(dir / "scanned.npy");
  const std::vector<BrdfSample> near_samples = ReadSamples(dir / "near.npy");
  ASSERT_EQ(far_samples.size(), near_samples.size());
  double worst = 0.0;
  for (size_t i = 0; i < far_samples.size(); ++i) {
    ASSERT_EQ(far_samples[i].image, near_samples[i].image);
    ASSERT_EQ(far_samples[i].pixel[0], near_samples[i].pixel[0]);
    ASSERT_EQ(far_samples[i].pixel[1], near_samples[i].pixel[1]);
    for (int c = 0; c < 3; ++c) {
      worst =
          std::max(worst, double(std::abs(far_samples[i].brdf[c] - near_samples[i].brdf[c]) / near_samples[i].brdf[c]));
    }
  }
  std::cout << "10 km scanner offset against none: largest relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-4);
}

// The dent's shadowed pixels, lit only by an unmodelled fill light (room light, interreflections) of 5 %
// of the point light: with visibility off they pass the signal floor and give samples far below the
// truth; with it on they are rejected as shadowed.
TEST(Squash, DentShadowsAreRejectedWithVisibility) {
  SetVerbosity(0);
  ScratchDir dir;
  const std::string s = dir / "dent";
  ASSERT_NO_FATAL_FAILURE(Synth("dent", s, 1.0, 0.05));
  const std::unique_ptr<BrdfModel> material = LoadTruthMaterial(s + "/truth.json");
  const Session session = Session::Load(s);
  const nlohmann::json truth = ReadJsonFile(s + "/truth.json");
  const nlohmann::json& shape = truth["generator"]["geometry"]["shape"];
  DentParams params;
  params.radius = shape["radius"];
  params.depth = shape["depth"];
  params.dent_half_angle_deg = shape["dent_half_angle_deg"];
  params.axis = Eigen::Vector3d(shape["axis"][0], shape["axis"][1], shape["axis"][2]);
  const DentedSphereSample dent(Eigen::Vector3d(shape["center"][0], shape["center"][1], shape["center"][2]), params);
  // Whether a sample's pixel centre truly sees a point of the dent in its own shadow.
  auto in_shadow = [&](const BrdfSample& sample) {
    const Rigid3d world_from_camera = session.photos[sample.image].camera_from_world->Inverse();
    const Eigen::Vector2d xy =
        session.camera.CamPlaneFromImage(Eigen::Vector2d(sample.pixel[0] + 0.5, sample.pixel[1] + 0.5));
    const Eigen::Vector3d direction = (world_from_camera.rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
    SurfaceHit hit, blocker;
    if (!dent.Intersect(world_from_camera.translation, direction, &hit)) return false;
    const Eigen::Vector3d to_light = session.lights[0].position - hit.point;
    return dent.Intersect(hit.point + 2e-6 * hit.normal, to_light.normalized(), &blocker) &&
           blocker.t < to_light.norm();
  };
  std::map<std::string, std::pair<size_t, size_t>> figures;  // visibility -> (samples, in true shadow)
  std::vector<double> shadow_errors;  // visibility off: |relative error| of the green channel in true shadow
  for (const std::string visibility : {"off", "on"}) {
    const std::string samples = dir / ("dent-" + visibility + ".npy");
    DerenderSession(TruthMeshSession(s, visibility), samples);
    size_t shadowed = 0;
    const std::vector<BrdfSample> all = ReadSamples(samples);
    for (const BrdfSample& sample : all) {
      if (!in_shadow(sample)) continue;
      ++shadowed;
      const Eigen::Vector3d wi(sample.wi[0], sample.wi[1], sample.wi[2]), wo(sample.wo[0], sample.wo[1], sample.wo[2]);
      const double f_true = material->Eval(wi, wo)[1];
      if (visibility == "off") shadow_errors.push_back(std::abs(sample.brdf[1] - f_true) / f_true);
    }
    figures[visibility] = {all.size(), shadowed};
    std::cout << "dent, visibility " << visibility << ": " << all.size() << " samples, " << shadowed
              << " from pixels in the dent's true shadow; " << Compare(samples, s + "/truth.json").BriefReport()
              << "\n";
  }
  // Off: the shadowed pixels are measured, and wrong by far more than the camera could explain.
  ASSERT_GT(figures["off"].second, 100u);
  std::nth_element(shadow_errors.begin(), shadow_errors.begin() + shadow_errors.size() / 2, shadow_errors.end());
  const double median_shadow_error = shadow_errors[shadow_errors.size() / 2];
  std::cout << "dent, visibility off: median |relative error| in the true shadow " << median_shadow_error << "\n";
  EXPECT_GT(median_shadow_error, 0.5);
  // On: none of them.
  EXPECT_GT(figures["off"].first, figures["on"].first);
  EXPECT_EQ(figures["on"].second, 0u);
}

}  // namespace
}  // namespace ibrdf
