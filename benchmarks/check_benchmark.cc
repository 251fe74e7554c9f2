// Speed of `ibrdf check`'s paired figures (CheckConsistency) on the demo's samples, on 1 and 2
// threads, at the automatic radius and at --match-deg 4 (every pair a joint fit over up to 64 samples
// a side).
//
//   build/benchmarks/check_benchmark [--benchmark_filter=...]
//
// The samples are the demo's: `ibrdf synth` defaults (a 4 cm bluepaint sphere, 20 photos of 800x600)
// derendered once per process (about 1.1 M samples), held in memory (reading the .npy is not timed).
// Time and "samples/s" are the whole process's CPU (MeasureProcessCPUTime), so figures hold on a
// loaded machine; "wall" is the wall-clock time. Figures go to docs/benchmarks.md ("Check and compare").
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "core/brdf_model.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/consistency.h"
#include "synth/synthetic.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

// The demo's samples, derendered once per process.
const std::vector<BrdfSample>& DemoSamples() {
  static const std::vector<BrdfSample> samples = [] {
    SetVerbosity(0);
    static const fs::path root = fs::temp_directory_path() / ("ibrdf-check-bench-" + std::to_string(getpid()));
    fs::create_directories(root);
    std::atexit([] { fs::remove_all(root); });
    const auto material = LoadMaterial(std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json");
    const std::string dir = (root / "demo").string();
    WriteSyntheticSession(SynthOptions(), *material, "bluepaint", dir, true);
    return Derender(Session::Load(dir), DerenderOptions()).samples;
  }();
  return samples;
}

// range(0): threads; range(1): --match-deg in degrees (0: automatic).
void BM_CheckConsistency(benchmark::State& state) {
  const std::vector<BrdfSample>& samples = DemoSamples();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  ConsistencyOptions options;
  options.match_deg = double(state.range(1));
  double wall_s = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const ConsistencyReport report = CheckConsistency(samples, options);
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!report.reciprocity.valid()) state.SkipWithError("no reciprocity figure");
    benchmark::DoNotOptimize(report.reciprocity.p95_rel_error);
  }
  state.counters["samples"] = double(samples.size());
  // Per CPU second (the benchmark's time is the process's CPU), and per wall second.
  state.counters["samples/s"] =
      benchmark::Counter(double(samples.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["wall_samples/s"] = double(samples.size()) * double(state.iterations()) / wall_s;
}
BENCHMARK(BM_CheckConsistency)
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({2, 4})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
