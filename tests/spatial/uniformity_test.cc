// The surface points found again from the samples' pixels, and the uniformity check on a uniform
// sphere (one material: ok) and on the same sphere with one half twice as bright (two materials: fail,
// and the map says where).
#include "spatial/uniformity.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sample_file.h"
#include "derender/derenderer.h"
#include "spatial/surface_points.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MakeSession;
using testing::ScratchDir;

// A grey sphere, 320 x 240 pixels, 4 photos, the default camera noise.
SynthOptions Small() {
  SynthOptions options;
  options.rig.width = 320;
  options.rig.height = 240;
  options.rig.num_photos = 4;
  return options;
}

const LambertianBrdf kGrey(Eigen::Vector3d(0.5, 0.4, 0.3));

struct Fixture {
  Session session;
  std::vector<BrdfSample> samples;
};

Fixture Derendered(const ScratchDir& dir) {
  Fixture f{Session::Load(MakeSession(dir / "session", Small(), kGrey)), {}};
  f.samples = DerenderAnalytic(f.session, DerenderOptions()).samples;
  EXPECT_GT(f.samples.size(), 20000u);
  return f;
}

UniformityOptions Coarse(const Session& session) {
  UniformityOptions options;
  options.cell_m = session.sample.radius / 6.0;  // about 60 samples a cell at this size
  return options;
}

TEST(SurfaceLocator, FindsEverySampleOnTheSphereAtItsExitantAngle) {
  ScratchDir dir;
  const Fixture f = Derendered(dir);
  const SurfaceLocator locator(f.session);
  size_t found = 0;
  double worst = 0.0;
  for (const BrdfSample& s : f.samples) {
    Eigen::Vector3d point;
    if (locator.Locate(s, &point) != SurfaceLocator::Outcome::kFound) continue;
    ++found;
    worst = std::max(worst, std::abs((point - f.session.sample.center).norm() - f.session.sample.radius));
  }
  EXPECT_EQ(found, f.samples.size());
  EXPECT_LT(worst, 1e-9);
}

// The same samples against a sphere moved by a tenth of its radius: their pixels now meet it at other
// angles or miss it, and the check says the samples are not this session's.
TEST(SurfaceLocator, SamplesOfAnotherGeometryAreNotFound) {
  ScratchDir dir;
  Fixture f = Derendered(dir);
  WriteSamples(dir / "samples.npy", f.samples);
  Session moved = f.session;
  moved.sample.center += Eigen::Vector3d(0.1 * moved.sample.radius, 0.0, 0.0);
  const SurfaceLocator locator(moved);
  size_t found = 0;
  for (const BrdfSample& s : f.samples) {
    Eigen::Vector3d point;
    if (locator.Locate(s, &point) == SurfaceLocator::Outcome::kFound) ++found;
  }
  EXPECT_LT(double(found), 0.5 * double(f.samples.size()));
  const UniformityResult result = MeasureUniformity(moved, dir / "samples.npy", kGrey, Coarse(moved));
  ASSERT_EQ(result.verdicts.size(), 2u);
  EXPECT_EQ(result.verdicts[1].check, "uniformity.located");
  EXPECT_EQ(result.verdicts[1].level, VerdictLevel::kFail);
}

TEST(Uniformity, OneMaterialIsUniform) {
  ScratchDir dir;
  const Fixture f = Derendered(dir);
  WriteSamples(dir / "samples.npy", f.samples);
  const UniformityResult result = MeasureUniformity(f.session, dir / "samples.npy", kGrey, Coarse(f.session));
  EXPECT_EQ(result.located, f.samples.size());
  EXPECT_GT(result.cells_scored, 100u);
  EXPECT_LT(result.deviating_fraction, 0.01) << result.BriefReport();
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(result.object_ratio[c], 1.0, 0.02);
    EXPECT_LT(result.spread[c], 1.1) << result.BriefReport();
  }
  EXPECT_EQ(result.verdicts[0].check, "uniformity.cells");
  EXPECT_EQ(result.verdicts[0].level, VerdictLevel::kOk) << result.verdicts[0].Line();
  EXPECT_EQ(result.verdicts[1].level, VerdictLevel::kOk) << result.verdicts[1].Line();
}

// The part of the seen surface beyond the samples' median x made twice as bright in red: about half
// the cells deviate, by 2x in red, and the map colours that part.
TEST(Uniformity, TwoMaterialsFailAndTheMapShowsWhere) {
  ScratchDir dir;
  Fixture f = Derendered(dir);
  const SurfaceLocator locator(f.session);
  std::vector<double> xs;
  for (const BrdfSample& s : f.samples) {
    Eigen::Vector3d point;
    ASSERT_EQ(locator.Locate(s, &point), SurfaceLocator::Outcome::kFound);
    xs.push_back(point.x());
  }
  std::vector<double> sorted = xs;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double split = sorted[sorted.size() / 2];
  for (size_t i = 0; i < f.samples.size(); ++i) {
    BrdfSample& s = f.samples[i];
    if (xs[i] > split) {
      s.brdf[0] *= 2.0f;
      s.sigma[0] *= 2.0f;
    }
  }
  WriteSamples(dir / "samples.npy", f.samples);
  const UniformityOptions options = Coarse(f.session);
  const UniformityResult result = MeasureUniformity(f.session, dir / "samples.npy", kGrey, options);
  EXPECT_GT(result.deviating_fraction, 0.3) << result.BriefReport();
  EXPECT_LT(result.deviating_fraction, 0.7) << result.BriefReport();
  EXPECT_EQ(result.verdicts[0].level, VerdictLevel::kFail) << result.verdicts[0].Line();
  EXPECT_GT(result.spread[0], 1.8);
  EXPECT_LT(result.spread[1], 1.1);
  // Cells well inside either half: the bright ones deviate, the others not.
  for (const UniformityCell& cell : result.cells) {
    if (!std::isfinite(cell.ratio[0])) continue;
    const double x = cell.centre.x() - split;
    if (std::abs(x) < 2.0 * result.cell_m) continue;
    EXPECT_EQ(cell.deviates, (x > 0.0) == (result.object_ratio[0] < 1.5)) << x;
  }
  const Image map = UniformityMap(f.session, dir / "samples.npy", result, options);
  ASSERT_EQ(map.width, f.session.camera.width);
  // The map photo's samples: red where the half is brighter (if the object's ratio is the dull half's)
  // or blue where it is dimmer, never both colours strong in one pixel.
  size_t coloured = 0;
  for (const BrdfSample& s : f.samples) {
    if (s.image != result.map_photo) continue;
    const float r = map.at(int(s.pixel[0]), int(s.pixel[1]), 0), b = map.at(int(s.pixel[0]), int(s.pixel[1]), 2);
    if (std::abs(r - b) > 0.5f) ++coloured;
  }
  EXPECT_GT(coloured, 1000u);
}

// The session of a sample file: the one given, else its sidecar's; a sidecar naming none is refused
// by its path.
TEST(SurfaceLocator, SessionOfSamplesIsGivenOrTheSidecars) {
  ScratchDir dir;
  EXPECT_EQ(SessionOfSamples(dir / "samples.npy", "given/session.json"), "given/session.json");
  std::ofstream(dir / "samples.npy.json") << R"({"session": "s/session.json"})";
  EXPECT_EQ(SessionOfSamples(dir / "samples.npy", ""), "s/session.json");
  std::ofstream(dir / "samples.npy.json") << R"({"format": "ibrdf-samples"})";
  try {
    SessionOfSamples(dir / "samples.npy", "");
    FAIL() << "a sidecar naming no session was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir / "samples.npy.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pass --session"), std::string::npos) << e.what();
  }
}

TEST(Uniformity, OptionsAreChecked) {
  std::string why;
  EXPECT_TRUE(UniformityOptions().Check(&why)) << why;
  UniformityOptions bad;
  bad.warn_fraction = 0.5;
  bad.fail_fraction = 0.1;
  EXPECT_FALSE(bad.Check(&why));
  bad = UniformityOptions();
  bad.min_cell_samples = 1;
  EXPECT_FALSE(bad.Check(&why));
}

}  // namespace
}  // namespace ibrdf
