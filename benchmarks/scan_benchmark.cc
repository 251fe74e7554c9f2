// Normals of a noisy synthetic scan (0.1 mm noise along the view on a 100 mm sphere or a
// 100 x 70 x 50 mm ellipsoid): local-plane normals (ours, TBB) against PCL's NormalEstimation (one
// thread) and NormalEstimationOMP, and against face normals; wall time and median angle error against
// the exact normals. Figures in docs/benchmarks.md.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "core/logging.h"
#include "core/statistics.h"
#include "scan/adapters.h"
#include "scan/local_plane_normals.h"
#include "scan/range_grid.h"
#include "synth/synthetic_scan.h"

namespace ibrdf {
namespace {

struct Scene {
  SyntheticRangeScanOptions synth;
  ScanMesh mesh;
  double radius_m = 0.0;
};

// The scan with `cols` x `cols` cells; shape 0 = sphere, 1 = ellipsoid. Built once per size.
const Scene& GetScene(int shape, int cols) {
  static std::map<std::pair<int, int>, std::unique_ptr<Scene>> cache;
  auto& scene = cache[{shape, cols}];
  if (!scene) {
    SetVerbosity(0);
    scene = std::make_unique<Scene>();
    scene->synth.cols = scene->synth.rows = cols;
    scene->synth.noise_m = 1e-4;
    if (shape == 1) scene->synth.radii = Eigen::Vector3d(0.05, 0.035, 0.025);
    scene->mesh = MakeSyntheticRangeScan(scene->synth);
    TessellateRangeGrid(RangeGridOptions(), &scene->mesh);
    scene->radius_m = LocalPlaneOptions().radius_spacing_factor * 2.0 * scene->synth.radii.x() / cols;
  }
  return *scene;
}

double MedianErrorDeg(const Scene& scene, const std::vector<Eigen::Vector3d>& normals, bool unoriented) {
  std::vector<double> errors;
  for (size_t i = 0; i < normals.size(); ++i) {
    if (normals[i].squaredNorm() == 0.0) continue;
    const Eigen::Vector3d truth = TrueEllipsoidNormal(scene.synth, scene.mesh.points[i]);
    double c = normals[i].dot(truth);
    if (unoriented) c = std::abs(c);
    errors.push_back(std::atan2(normals[i].cross(truth).norm(), c) * 180.0 / M_PI);
  }
  return PercentileInPlace(&errors, 0.5);
}

void SetCounters(benchmark::State& state, const Scene& scene, double error_deg) {
  state.counters["points"] = static_cast<double>(scene.mesh.points.size());
  state.counters["median_error_deg"] = error_deg;
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(scene.mesh.points.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_LocalPlaneNormals(benchmark::State& state) {
  const Scene& scene = GetScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(2)));
  LocalPlaneOptions options;
  options.radius_m = scene.radius_m;
  LocalPlaneResult result;
  for (auto _ : state) {
    result = FitLocalPlanes(scene.mesh, options);
    benchmark::DoNotOptimize(result.normals.data());
  }
  SetCounters(state, scene, MedianErrorDeg(scene, result.normals, false));
}

void BM_PclNormalEstimation(benchmark::State& state) {
  const Scene& scene = GetScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  std::vector<Eigen::Vector3d> normals;
  for (auto _ : state) {
    normals = scan_adapters::PclNormals(scene.mesh.points, scene.radius_m, static_cast<int>(state.range(2)));
    benchmark::DoNotOptimize(normals.data());
  }
  SetCounters(state, scene, MedianErrorDeg(scene, normals, true));
}

// Face normals, as a derenderer would take them from the hit triangle: error at the face centroids.
void BM_FaceNormals(benchmark::State& state) {
  const Scene& scene = GetScene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  std::vector<Eigen::Vector3d> normals(scene.mesh.faces.size());
  for (auto _ : state) {
    for (size_t f = 0; f < scene.mesh.faces.size(); ++f) normals[f] = FaceNormal(scene.mesh, f);
    benchmark::DoNotOptimize(normals.data());
  }
  std::vector<double> errors;
  for (size_t f = 0; f < normals.size(); ++f) {
    const Eigen::Vector3i& v = scene.mesh.faces[f];
    const Eigen::Vector3d centre = (scene.mesh.points[v[0]] + scene.mesh.points[v[1]] + scene.mesh.points[v[2]]) / 3.0;
    const Eigen::Vector3d truth = TrueEllipsoidNormal(scene.synth, centre);
    errors.push_back(std::atan2(normals[f].cross(truth).norm(), normals[f].dot(truth)) * 180.0 / M_PI);
  }
  SetCounters(state, scene, PercentileInPlace(&errors, 0.5));
}

// Args: shape (0 sphere, 1 ellipsoid), grid columns (234: ~40 k points at 0.43 mm; 1170: ~1 M points
// at 0.085 mm), threads.
void Sizes(benchmark::internal::Benchmark* b, bool threaded) {
  for (int shape : {0, 1}) {
    for (int cols : {234, 1170}) {
      b->Args({shape, cols, 1});
      if (threaded) b->Args({shape, cols, 2});
    }
  }
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_LocalPlaneNormals)->Apply([](benchmark::internal::Benchmark* b) { Sizes(b, true); });
BENCHMARK(BM_PclNormalEstimation)->Apply([](benchmark::internal::Benchmark* b) { Sizes(b, true); });
BENCHMARK(BM_FaceNormals)->Apply([](benchmark::internal::Benchmark* b) { Sizes(b, false); });

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
