// Speed of the reconstruct stage on the demo's samples: the regression's set-up, the
// MERL tabulation, the RGL .bsdf export and the whole stage, each on 1 and 2 threads.
//
//   build/benchmarks/reconstruct_benchmark [--benchmark_filter=...]
//
// The samples are the demo's: `ibrdf synth` defaults (a 4 cm bluepaint sphere, 20 photos of 800x600)
// derendered once per process (about 1.1 M samples). The CPU column is the whole process's CPU
// (MeasureProcessCPUTime), so CPU / wall shows how well a part uses the threads. Figures go to
// docs/benchmarks.md ("Reconstruct").
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "core/brdf_coords.h"
#include "core/brdf_model.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/bsdf_export.h"
#include "reconstruct/local_regression.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/reconstruction_stage.h"
#include "synth/synthetic.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

const fs::path& Root() {
  static const fs::path root = fs::temp_directory_path() / ("ibrdf-reconstruct-bench-" + std::to_string(getpid()));
  return root;
}

// The demo's samples, derendered once per process.
const std::vector<BrdfSample>& DemoSamples() {
  static const std::vector<BrdfSample> samples = [] {
    SetVerbosity(0);
    fs::create_directories(Root());
    std::atexit([] { fs::remove_all(Root()); });
    const auto material = LoadMaterial(std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json");
    const std::string dir = (Root() / "demo").string();
    WriteSyntheticSession(SynthOptions(), *material, "bluepaint", dir, true);
    return Derender(Session::Load(dir), DerenderOptions()).samples;
  }();
  return samples;
}

void BM_BuildRegression(benchmark::State& state) {
  const std::vector<BrdfSample>& samples = DemoSamples();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  for (auto _ : state) {
    const LocalRegression regression(samples, LocalRegressionOptions());
    benchmark::DoNotOptimize(regression.points());
  }
  state.counters["samples"] = double(samples.size());
}
BENCHMARK(BM_BuildRegression)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_TabulateMerl(benchmark::State& state) {
  const LocalRegression regression(DemoSamples(), LocalRegressionOptions());
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  TabulateSummary summary;
  for (auto _ : state) {
    const MerlTable table = TabulateMerl(regression, TabulateOptions(), &summary);
    benchmark::DoNotOptimize(table.Measured(0));
  }
  state.counters["evaluations"] = double(summary.evaluations);
  state.counters["evaluations/s"] =
      benchmark::Counter(double(summary.evaluations) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TabulateMerl)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_BuildRglBsdf(benchmark::State& state) {
  const LocalRegression regression(DemoSamples(), LocalRegressionOptions());
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  const BrdfBatch source = [&](const std::vector<Eigen::Vector3d>& wi, const std::vector<Eigen::Vector3d>& wo,
                               std::vector<Eigen::Vector3d>* f) {
    std::vector<Eigen::Vector3d> uvw(wi.size());
    for (size_t i = 0; i < wi.size(); ++i) uvw[i] = RegressionCoordinates(wi[i], wo[i]);
    const std::vector<Estimate> estimates = regression.EvaluateMany(uvw, nullptr);
    f->resize(wi.size());
    for (size_t i = 0; i < wi.size(); ++i) (*f)[i] = estimates[i].value;
  };
  BsdfExportSummary summary;
  for (auto _ : state) {
    const TensorFile file = BuildRglBsdf(source, "benchmark", BsdfExportOptions(), &summary);
    benchmark::DoNotOptimize(file.size());
  }
  state.counters["evaluations"] = double(summary.evaluations);
}
BENCHMARK(BM_BuildRglBsdf)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// The whole stage as `ibrdf reconstruct SAMPLES --truth TRUTH` runs it after reading the samples:
// regression, fits (range(1) = 1) or not, tabulation, score against the truth, .bsdf export and its
// check, every file written.
void BM_ReconstructStage(benchmark::State& state) {
  const std::vector<BrdfSample>& samples = DemoSamples();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  ReconstructOptions options;
  options.fits = state.range(1) != 0;
  options.truth_file = (Root() / "demo" / "truth.json").string();
  options.overwrite = true;
  options.name = "bluepaint";
  const std::string out = (Root() / "reconstruction").string();
  for (auto _ : state) {
    const ReconstructResult result = Reconstruct(samples, options, out);
    if (!result.success) state.SkipWithError("reconstruct failed");
  }
}
BENCHMARK(BM_ReconstructStage)
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Iterations(1);

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
