// Speed of the derenderer against the floor it should approach: decoding the same photos.
//
//   build/benchmarks/derender_benchmark [--benchmark_filter=...]
//
// The session is the demo's: a 4 cm bluepaint sphere, 20 photos of 800x600, 16-bit PNG with the
// default camera noise (and the same as float EXR). Rates are pixels/s of photo processed and
// samples/s produced; figures go to docs/benchmarks.md. The mesh path runs on the same photos with
// the sphere as a UV mesh (262k faces, exact normals): the whole stage, and the pixel rays alone in
// each of Embree's ray modes against the analytic sphere. scripts/bench-open3d-raycast is the
// baseline a user would write instead (Open3D's RaycastingScene and NumPy on the same photos).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/analytic_sample.h"
#include "derender/derenderer.h"
#include "derender/mesh_sample.h"
#include "radiometry/radiance_image.h"
#include "scan/convexity.h"
#include "scan/mesh_file.h"
#include "scan/ply_io.h"
#include "synth/synthetic.h"
#include "synth/synthetic_scan.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

// Sessions are written once per process into a temporary folder.
const Session& BenchSession(bool exr) {
  static const fs::path root = fs::temp_directory_path() / ("ibrdf-bench-" + std::to_string(getpid()));
  static std::map<bool, Session> sessions;
  auto it = sessions.find(exr);
  if (it == sessions.end()) {
    SetVerbosity(0);
    fs::create_directories(root);
    const auto material = LoadMaterial(std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json");
    SynthOptions options;
    if (exr) options.effects.bits = 0;
    const std::string dir = (root / (exr ? "exr" : "png")).string();
    WriteSyntheticSession(options, *material, "bluepaint", dir, true);
    it = sessions.emplace(exr, Session::Load(dir)).first;
    std::atexit([] { fs::remove_all(root); });
  }
  return it->second;
}

// The PNG session with its sample as a UV-sphere mesh of 256 rings x 512 segments (131k points,
// 262k faces: a fine scan of a 4 cm sphere), written beside the session once.
const Session& BenchMeshSession(Visibility visibility) {
  static std::map<Visibility, Session> sessions;
  auto it = sessions.find(visibility);
  if (it == sessions.end()) {
    Session session = BenchSession(false);
    const std::string file = session.directory + "/sphere-mesh.ply";
    if (!fs::exists(file)) WritePly(file, MakeUvEllipsoid(Eigen::Vector3d::Constant(session.sample.radius), 256, 512));
    session.sample = SampleSpec();
    session.sample.kind = SampleSpec::Kind::kMesh;
    session.sample.mesh_file = "sphere-mesh.ply";
    session.sample.visibility = visibility;
    it = sessions.emplace(visibility, session).first;
  }
  return it->second;
}

void SetRates(benchmark::State& state, const Session& session, uint64_t samples) {
  const double pixels = double(session.camera.width) * session.camera.height * session.photos.size();
  state.counters["pixels/s"] = benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  if (samples > 0) {
    state.counters["samples/s"] = benchmark::Counter(double(samples), benchmark::Counter::kIsIterationInvariantRate);
  }
}

// The floor: decode every photo (in parallel over photos, as the derenderer does).
void BM_DecodePhotos(benchmark::State& state) {
  const Session& session = BenchSession(state.range(0) == 1);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  for (auto _ : state) {
    std::vector<float> sums(session.photos.size());
    tbb::parallel_for(size_t(0), session.photos.size(), [&](size_t i) {
      const Image image = ReadImage(session.PhotoPath(i));
      sums[i] = image.pixels[image.pixels.size() / 2];
    });
    benchmark::DoNotOptimize(sums.data());
  }
  SetRates(state, session, 0);
}

// The whole stage: decode and derender every photo.
void BM_DerenderSession(benchmark::State& state) {
  const Session& session = BenchSession(state.range(0) == 1);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  uint64_t samples = 0;
  for (auto _ : state) {
    const DerenderResult result = DerenderAnalytic(session, DerenderOptions());
    samples = result.samples.size();
    benchmark::DoNotOptimize(result.samples.data());
  }
  SetRates(state, session, samples);
}

// The per-pixel kernel alone (the stage's DerenderSetup::DerenderPhoto, one thread), on photos decoded
// and prepared beforehand (DerenderSetup::ReadPhoto): the geometry, the merge of the pixels that reach
// the radiometric tests and the samples' assembly.
void BM_DerenderDecodedPhotos(benchmark::State& state) {
  const Session& session = BenchSession(false);
  const DerenderSetup setup(session, DerenderOptions());
  std::vector<std::unique_ptr<RadianceWindow>> images;
  for (size_t i = 0; i < setup.NumPhotos(); ++i) {
    images.push_back(std::make_unique<RadianceWindow>());
    setup.ReadPhoto(i, images.back().get());
  }
  PhotoSamples photo;
  uint64_t samples = 0;
  for (auto _ : state) {
    samples = 0;
    for (size_t i = 0; i < images.size(); ++i) {
      setup.DerenderPhoto(i, *images[i], false, &photo);
      for (const std::vector<BrdfSample>& block : photo.blocks) samples += block.size();
      benchmark::DoNotOptimize(photo.blocks.data());
    }
  }
  SetRates(state, session, samples);
}

// The mesh path, whole stage (decode included), on the same photos: shadow rays off (the sphere is
// convex) or on (9 shadow rays per lit pixel: the worst case of a non-convex sample).
void BM_DerenderMeshSession(benchmark::State& state) {
  const Session& session = BenchMeshSession(state.range(0) == 1 ? Visibility::kOn : Visibility::kOff);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  uint64_t samples = 0;
  double decode_s = 0.0;
  for (auto _ : state) {
    const DerenderResult result = Derender(session, DerenderOptions());
    samples = result.samples.size();
    decode_s = result.summary.decode_s;
    benchmark::DoNotOptimize(result.samples.data());
  }
  SetRates(state, session, samples);
  state.counters["decode_cpu_s"] = decode_s;  // of the last iteration, summed over threads
}

// The mesh path's set-up on a 409600-face mesh (a UV sphere of 320 rings x 640 segments written as
// binary PLY): what derender does before its pixel loop when the mesh has no scan sidecar: read the
// file, build the Embree scene and compute the convexity report (side by side, 2 threads).
void BM_MeshSetUp(benchmark::State& state) {
  const Session& session = BenchSession(false);
  const std::string file = session.directory + "/sphere-mesh-400k.ply";
  if (!fs::exists(file)) WritePly(file, MakeUvEllipsoid(Eigen::Vector3d::Constant(session.sample.radius), 320, 640));
  size_t faces = 0;
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  for (auto _ : state) {
    const ScanMesh mesh = ReadTriangleMeshFile(file);
    // As the derenderer does (PrepareMeshPath): the scene and the convexity report side by side.
    std::unique_ptr<MeshSample> sample;
    ConvexityReport report;
    tbb::parallel_invoke([&] { sample = std::make_unique<MeshSample>(mesh, Sim3d(), file); },
                         [&] { report = ReportConvexity(mesh, ConvexityOptions()); });
    faces = sample->NumFaces();
    benchmark::DoNotOptimize(report.fraction_within);
  }
  state.counters["faces"] = double(faces);
}

// The rays alone: every pixel centre of the 20 photos (800x600) cast at the sphere, one thread, row by
// row as the derenderer does. Arg 0: the analytic sphere; 1, 2, 3: the mesh with rtcIntersect1,
// rtcIntersect8 packets, rtcIntersect1M streams. Rate: rays/s.
void BM_PixelRays(benchmark::State& state) {
  const Session& session = BenchSession(false);
  const std::vector<Eigen::Vector2f> rays = PixelRays(session.camera);
  const auto sphere = AnalyticSample::Create(session.sample);
  const ScanMesh uv = MakeUvEllipsoid(Eigen::Vector3d::Constant(session.sample.radius), 256, 512);
  MeshSample mesh(uv, Sim3d(), "uv sphere");
  const int mode = int(state.range(0));
  if (mode > 0) mesh.set_ray_mode(MeshSample::RayMode(mode - 1));
  const int width = session.camera.width, height = session.camera.height;
  std::vector<Eigen::Vector3d> directions(width);
  std::vector<SurfaceHit> hits(width);
  std::unique_ptr<bool[]> found(new bool[width]);
  uint64_t hit_count = 0;
  for (auto _ : state) {
    hit_count = 0;
    for (size_t i = 0; i < session.photos.size(); ++i) {
      const Rigid3d world_from_camera = session.photos[i].camera_from_world->Inverse();
      const Eigen::Matrix3d rotation = world_from_camera.rotation.toRotationMatrix();
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const Eigen::Vector2f& xy = rays[size_t(y) * width + x];
          directions[x] = (rotation * Eigen::Vector3d(xy.x(), xy.y(), 1.0)).normalized();
        }
        if (mode == 0) {
          for (int x = 0; x < width; ++x)
            found[x] = sphere->Intersect(world_from_camera.translation, directions[x], &hits[x]);
        } else {
          mesh.IntersectBatch(world_from_camera.translation, directions.data(), width, hits.data(), found.get());
        }
        for (int x = 0; x < width; ++x) hit_count += found[x];
      }
    }
    benchmark::DoNotOptimize(hit_count);
  }
  state.counters["rays/s"] =
      benchmark::Counter(double(width) * height * session.photos.size(), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["hits"] = double(hit_count);
}

// Args: {exr (0 = 16-bit PNG, 1 = float EXR), threads}.
// The CPU column is the whole process's CPU time (all threads): on a loaded machine the ratio of
// derender to decode CPU is the figure to trust, wall time only on an idle one.
BENCHMARK(BM_DecodePhotos)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_DerenderSession)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_DerenderDecodedPhotos)->Unit(benchmark::kMillisecond)->UseRealTime();
// Args: {shadow rays (0 off, 1 on), threads}.
BENCHMARK(BM_DerenderMeshSession)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({1, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_MeshSetUp)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_PixelRays)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
