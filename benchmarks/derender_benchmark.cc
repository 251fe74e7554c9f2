// Speed of the analytic derenderer against the floor it should approach: decoding the same photos.
//
//   build/benchmarks/derender_benchmark [--benchmark_filter=...]
//
// The session is the demo's: a 4 cm bluepaint sphere, 20 photos of 800x600, 16-bit PNG with the
// default camera noise (and the same as float EXR). Rates are pixels/s of photo processed and
// samples/s produced; figures go to docs/benchmarks.md.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "core/session.h"
#include "derender/analytic_sample.h"
#include "derender/derenderer.h"
#include "derender/radiance_image.h"
#include "derender/synthetic.h"

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

// The per-pixel geometry alone, on radiance images decoded and linearized beforehand, one thread.
void BM_DerenderDecodedPhotos(benchmark::State& state) {
  const Session& session = BenchSession(false);
  std::vector<RadianceImage> images;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    images.push_back(ReadRadianceImage(session, {i}, DerenderOptions().min_signal));
  }
  const std::vector<Eigen::Vector2f> rays = PixelRays(session.camera);
  const auto sample = AnalyticSample::Create(session.sample);
  uint64_t samples = 0;
  for (auto _ : state) {
    std::vector<BrdfSample> out;
    out.reserve(size_t(session.camera.width) * session.camera.height * images.size());
    RejectionCounts rejected;
    for (size_t i = 0; i < images.size(); ++i) {
      DerenderPhoto(session, i, images[i], rays, *sample, DerenderOptions(), &out, &rejected);
    }
    samples = out.size();
    benchmark::DoNotOptimize(out.data());
  }
  SetRates(state, session, samples);
}

// Args: {exr (0 = 16-bit PNG, 1 = float EXR), threads}.
BENCHMARK(BM_DecodePhotos)->Args({0, 1})->Args({0, 2})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DerenderSession)->Args({0, 1})->Args({0, 2})->Args({1, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DerenderDecodedPhotos)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
