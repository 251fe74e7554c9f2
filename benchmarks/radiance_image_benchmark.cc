// Speed of the radiometric chain (radiometry/radiance_image.h) against decoding the same photos: it
// runs for every pixel of every photo, so it should cost little beside the decode.
//
//   build/benchmarks/radiance_image_benchmark [--benchmark_filter=...]
//
// Sessions: the demo's camera (800x600, 16-bit PNG, default noise), 4 poses of a bluepaint sphere:
// linear; sRGB with black level, vignetting (a flat field) and a white reference; and linear with a
// bracket of 3 exposures per pose. Argument: TBB threads. Figures go to docs/benchmarks.md.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "calibrate/white_reference_intensity.h"
#include "core/brdf_model.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "core/session.h"
#include "radiometry/radiance_image.h"
#include "synth/synthetic.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

enum Kind { kLinear = 0, kSrgbFlat = 1, kBracket = 2 };

const Session& BenchSession(int kind) {
  static const fs::path root = fs::temp_directory_path() / ("ibrdf-radiance-bench-" + std::to_string(getpid()));
  static std::map<int, Session> sessions;
  auto it = sessions.find(kind);
  if (it == sessions.end()) {
    SetVerbosity(0);
    fs::create_directories(root);
    const auto material = LoadMaterial(std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json");
    SynthOptions options;
    options.rig.num_photos = 4;
    if (kind == kSrgbFlat) {
      options.effects.curve = SensorCurve::kSrgb;
      options.effects.black_level = 0.03;
      options.effects.vignetting = 0.4;
      options.radiometry.light_unknown = true;
    }
    if (kind == kBracket) options.radiometry.brackets = 3;
    const std::string dir = (root / std::to_string(kind)).string();
    WriteSyntheticSession(options, *material, "bluepaint", dir, true);
    it = sessions.emplace(kind, Session::Load(dir)).first;
    if (sessions.size() == 1) std::atexit([] { fs::remove_all(root); });
  }
  return it->second;
}

// The floor: decoding every measurement photo, one after another.
void BM_DecodePhotos(benchmark::State& state) {
  const Session& session = BenchSession(static_cast<int>(state.range(0)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
  for (auto _ : state) {
    for (size_t i = 0; i < session.photos.size(); ++i) benchmark::DoNotOptimize(ReadImage(session.PhotoPath(i)));
  }
  state.counters["pixels/s"] = benchmark::Counter(
      double(state.iterations()) * session.photos.size() * session.camera.width * session.camera.height,
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodePhotos)->Arg(kLinear)->Arg(kSrgbFlat)->Arg(kBracket)->Unit(benchmark::kMillisecond)->UseRealTime();

// Decode + radiance image of every exposure group; args: session kind, TBB threads.
void BM_RadianceImages(benchmark::State& state) {
  const Session& session = BenchSession(static_cast<int>(state.range(0)));
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, state.range(1));
  const std::vector<std::vector<size_t>> groups = ExposureGroups(session);
  for (auto _ : state) {
    for (const auto& group : groups) benchmark::DoNotOptimize(ReadRadianceImage(session, group, 0.002));
  }
  state.counters["pixels/s"] = benchmark::Counter(
      double(state.iterations()) * session.photos.size() * session.camera.width * session.camera.height,
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RadianceImages)
    ->Args({kLinear, 1})
    ->Args({kLinear, 2})
    ->Args({kSrgbFlat, 1})
    ->Args({kSrgbFlat, 2})
    ->Args({kBracket, 1})
    ->Args({kBracket, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The white reference step of the sRGB session (one photo).
void BM_LightCalibration(benchmark::State& state) {
  const Session& session = BenchSession(kSrgbFlat);
  for (auto _ : state) {
    LightCalibrationReport report;
    benchmark::DoNotOptimize(ApplyLightCalibration(session, &report));
  }
}
BENCHMARK(BM_LightCalibration)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace ibrdf

BENCHMARK_MAIN();
