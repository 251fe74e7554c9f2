// Tests of the streamed derender stage (derender/derenderer.h, DerenderToFile): the file it writes photo
// by photo is byte for byte WriteSamples of the in-memory stage's samples (Derender), with and without a
// colour chart's matrix (applied photo by photo), its summary that of the in-memory stage, and a stage
// that fails part-way leaves neither the file nor its sidecar nor a temporary behind.
#include "derender/derenderer.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/sample_file.h"
#include "derender/colour_correction.h"
#include "tests/error_of.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A noise-free blue paint sphere, 200 x 150 pixels, `photos` photos.
Session BluepaintSession(const testing::ScratchDir& dir, int photos) {
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = photos;
  options.effects = CameraEffects::None();
  const auto material = LoadMaterial(testing::MaterialPath("bluepaint"));
  return Session::Load(testing::MakeSession(dir / "session", options, *material));
}

// The sidecar's figures without the timings (the only part that differs run to run).
nlohmann::json Counts(const Session& session, const DerenderSummary& summary) {
  nlohmann::json sidecar = DerenderSidecar(session, DerenderOptions(), summary);
  sidecar.erase("timings_s");
  return sidecar;
}

void ExpectStreamedEqualsInMemory(const Session& session, const testing::ScratchDir& dir) {
  const DerenderResult in_memory = Derender(session, DerenderOptions());
  ASSERT_GT(in_memory.samples.size(), 1000u);
  WriteSamples(dir / "whole.npy", in_memory.samples);
  const DerenderSummary streamed = DerenderToFile(session, DerenderOptions(), dir / "streamed.npy");
  const std::string whole = ReadBytes(dir / "whole.npy");
  EXPECT_EQ(whole.size(), ReadBytes(dir / "streamed.npy").size());
  EXPECT_TRUE(whole == ReadBytes(dir / "streamed.npy")) << "the streamed file differs from WriteSamples'";
  EXPECT_EQ(streamed.accepted, in_memory.samples.size());
  EXPECT_EQ(Counts(session, streamed), Counts(session, in_memory.summary));
}

TEST(DerenderStream, FileIsByteIdenticalToWriteSamplesOfTheInMemoryStage) {
  testing::ScratchDir dir;
  ExpectStreamedEqualsInMemory(BluepaintSession(dir, 7), dir);
}

// A chart matrix with a strong negative red-from-green term (colour_correction_test.cc): channels
// marked unmeasured photo by photo give the file and counts of the correction applied to all at once.
TEST(DerenderStream, ColourCorrectedFileIsByteIdenticalToo) {
  testing::ScratchDir dir;
  Session session = BluepaintSession(dir, 5);
  Eigen::Matrix3d m;
  m << 1.0, -0.9, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0;
  session.colour_chart = ColourChartSpec();
  session.colour_chart->matrix = m;
  ExpectStreamedEqualsInMemory(session, dir);
  // The correction applied once to all the uncorrected samples (DerenderAll applies none), as the stage
  // did before it corrected photo by photo: the same rows and counts.
  DerenderResult once = DerenderSetup(session, DerenderOptions()).DerenderAll();
  ColourCorrectionCounts counts;
  ApplyColourCorrection(session, &once.samples, &counts);
  WriteSamples(dir / "once.npy", once.samples);
  EXPECT_TRUE(ReadBytes(dir / "once.npy") == ReadBytes(dir / "streamed.npy"));
  const DerenderSummary streamed = DerenderToFile(session, DerenderOptions(), dir / "streamed.npy");
  EXPECT_GT(streamed.colour_negative[0], 100u);
  EXPECT_EQ(streamed.colour_negative, counts.negative);
  EXPECT_EQ(streamed.rejected.at("colour_unmeasured"), counts.dropped);
}

// The last photo is cut short (its header, which the stage checks before decoding any photo, is intact,
// so its decode fails): the stage stops after the first photos' samples went to the temporary file, and neither the sample file nor its sidecar appears, nor a temporary stays; an earlier run's
// files are left as they were.
TEST(DerenderStream, StageThatFailsPartWayLeavesNoFile) {
  testing::ScratchDir dir;
  const Session session = BluepaintSession(dir, 8);
  fs::create_directories(dir / "out");
  const std::string out = dir / "out/samples.npy";
  const std::string photo = session.AbsolutePath(session.photos.back().file);
  ASSERT_TRUE(fs::is_regular_file(photo)) << photo;
  fs::resize_file(photo, fs::file_size(photo) / 2);
  const std::string message = testing::ErrorOf([&] { DerenderToFile(session, DerenderOptions(), out); });
  EXPECT_NE(message.find(fs::path(photo).filename().string()), std::string::npos) << message;
  EXPECT_EQ(message.find("no BRDF samples"), std::string::npos) << message;
  EXPECT_TRUE(fs::is_empty(dir / "out")) << "files left in " << dir / "out";
  std::ofstream(out) << "earlier";
  std::ofstream(SidecarPath(out)) << "{}";
  testing::ErrorOf([&] { DerenderToFile(session, DerenderOptions(), out); });
  EXPECT_EQ(ReadBytes(out), "earlier");
  EXPECT_EQ(ReadBytes(SidecarPath(out)), "{}");
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "out")) files += entry.is_regular_file();
  EXPECT_EQ(files, 2u);
}

}  // namespace
}  // namespace ibrdf
