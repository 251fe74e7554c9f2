// Running COLMAP: the three calls (CPU, the session's intrinsics, the photos by their session names),
// and the error paths: the binary missing, a step failing, the mapper finding no model; the work folder
// appears only when a model was found. Stand-in `colmap` scripts play the real binary's part here; the
// real run on a synthetic session is recorded in docs/align-colmap.md.
#include "align/colmap_runner.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "align/colmap_model.h"
#include "core/error.h"
#include "tests/error_of.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

using testing::ErrorOf;

std::string Script(const std::string& path, const std::string& body) {
  std::ofstream(path) << "#!/bin/sh\n" << body;
  fs::permissions(path, fs::perms::owner_all);
  return path;
}

Session SmallSession(const ScratchDir& dir) {
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 3;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  return Session::Load(MakeSession(dir / "s", options, *material));
}

bool Has(const std::vector<std::string>& arguments, const std::string& key, const std::string& value) {
  const auto it = std::find(arguments.begin(), arguments.end(), key);
  return it != arguments.end() && it + 1 != arguments.end() && *(it + 1) == value;
}

TEST(ColmapRunner, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ColmapRunnerOptions().Check(&why)) << why;
}

TEST(ColmapRunner, CommandsRunOnTheCpuWithTheSessionsCamera) {
  ScratchDir dir;
  const Session session = SmallSession(dir);
  ColmapRunnerOptions options;
  options.fix_intrinsics = true;
  const std::vector<ColmapCommand> commands = ColmapCommands(session, "/w", options);
  ASSERT_EQ(commands.size(), 3u);
  EXPECT_EQ(commands[0].step, "feature_extractor");
  EXPECT_TRUE(Has(commands[0].arguments, "--SiftExtraction.use_gpu", "0"));
  EXPECT_TRUE(Has(commands[0].arguments, "--database_path", "/w/database.db"));
  EXPECT_TRUE(Has(commands[0].arguments, "--image_path", "/w/images"));
  EXPECT_TRUE(Has(commands[0].arguments, "--image_list_path", "/w/image-list.txt"));
  EXPECT_TRUE(Has(commands[0].arguments, "--ImageReader.camera_model", "OPENCV"));
  EXPECT_TRUE(Has(commands[0].arguments, "--ImageReader.single_camera", "1"));
  const auto params =
      std::find(commands[0].arguments.begin(), commands[0].arguments.end(), "--ImageReader.camera_params");
  ASSERT_NE(params, commands[0].arguments.end());
  EXPECT_EQ(std::count((params + 1)->begin(), (params + 1)->end(), ','), 7);
  EXPECT_EQ(commands[1].step, "exhaustive_matcher");
  EXPECT_TRUE(Has(commands[1].arguments, "--SiftMatching.use_gpu", "0"));
  EXPECT_EQ(commands[2].step, "mapper");
  EXPECT_TRUE(Has(commands[2].arguments, "--output_path", "/w/sparse"));
  EXPECT_TRUE(Has(commands[2].arguments, "--Mapper.ba_refine_focal_length", "0"));
  options.fix_intrinsics = false;
  options.use_session_intrinsics = false;
  const std::vector<ColmapCommand> free = ColmapCommands(session, "/w", options);
  EXPECT_FALSE(Has(free[2].arguments, "--Mapper.ba_refine_focal_length", "0"));
  EXPECT_EQ(std::find(free[0].arguments.begin(), free[0].arguments.end(), "--ImageReader.camera_params"),
            free[0].arguments.end());
}

TEST(ColmapRunner, MissingBinaryIsAClearError) {
  ScratchDir dir;
  const Session session = SmallSession(dir);
  ColmapRunnerOptions options;
  options.binary = dir / "no-such-colmap";
  std::string message = ErrorOf([&] { RunColmap(session, dir / "work", options, false); });
  EXPECT_NE(message.find("no-such-colmap: the COLMAP executable was not found"), std::string::npos) << message;
  options.binary = "ibrdf-no-such-colmap-on-path";
  message = ErrorOf([&] { RunColmap(session, dir / "work", options, false); });
  EXPECT_NE(message.find("was not found"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "work"));
}

TEST(ColmapRunner, FailingStepNamesItselfAndItsLog) {
  ScratchDir dir;
  const Session session = SmallSession(dir);
  ColmapRunnerOptions options;
  options.binary =
      Script(dir / "colmap",
             "echo \"step $1\"\n[ \"$1\" = exhaustive_matcher ] && { echo 'boom: out of memory'; exit 3; }\nexit 0\n");
  const std::string message = ErrorOf([&] { RunColmap(session, dir / "work", options, false); });
  EXPECT_NE(message.find("exhaustive_matcher: failed with exit code 3"), std::string::npos) << message;
  EXPECT_NE(message.find("boom: out of memory"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "work"));
}

TEST(ColmapRunner, NoModelIsAClearError) {
  ScratchDir dir;
  const Session session = SmallSession(dir);
  ColmapRunnerOptions options;
  options.binary = Script(dir / "colmap", "echo 'No good initial image pair found.'\nexit 0\n");
  const std::string message = ErrorOf([&] { RunColmap(session, dir / "work", options, false); });
  EXPECT_NE(message.find("mapper: found no model in 3 photos"), std::string::npos) << message;
  EXPECT_NE(message.find("No good initial image pair found."), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "work"));
}

// A stand-in mapper that writes a model of the photos it was given (their names from the image list),
// headless: the work folder then appears with the copies, the logs and the model.
TEST(ColmapRunner, ModelAppearsWithTheWorkFolder) {
  ScratchDir dir;
  const Session session = SmallSession(dir);
  ColmapRunnerOptions options;
  options.binary = Script(dir / "colmap",
                          "[ \"$QT_QPA_PLATFORM\" = offscreen ] || exit 9\n"
                          "if [ \"$1\" = mapper ]; then\n"
                          "  while [ $# -gt 0 ]; do case \"$1\" in --output_path) out=\"$2\";; --image_list_path) "
                          "list=\"$2\";; esac; shift; done\n"
                          "  mkdir -p \"$out/0\"\n"
                          "  echo '1 PINHOLE 200 150 100 100 100 75' > \"$out/0/cameras.txt\"\n"
                          "  : > \"$out/0/images.txt\"; i=1\n"
                          "  while read name; do echo \"$i 1 0 0 0 0 0 $i 1 $name\" >> \"$out/0/images.txt\"; echo >> "
                          "\"$out/0/images.txt\"; i=$((i+1)); done < \"$list\"\n"
                          "  : > \"$out/0/points3D.txt\"\n"
                          "  touch \"$out/0/images.bin\"\n"
                          "fi\nexit 0\n");
  // The stand-in writes text; the runner looks for images.bin, which it touches, and reads text when
  // cameras.bin is absent.
  const ColmapRunResult result = RunColmap(session, dir / "work", options, false);
  EXPECT_EQ(result.registered_images, 3);
  EXPECT_EQ(result.models, 1);
  EXPECT_EQ(result.model_dir, dir / "work/sparse/0");
  EXPECT_TRUE(fs::exists(dir / "work/images/photos/000.png"));
  EXPECT_TRUE(fs::exists(dir / "work/logs/mapper.log"));
  const ColmapModel model = ColmapModel::Read(result.model_dir);
  EXPECT_EQ(model.images.at(1).name, "photos/000.png");
  // Run again into the same folder: refused unless overwriting.
  EXPECT_THROW(RunColmap(session, dir / "work", options, false), Error);
  EXPECT_EQ(RunColmap(session, dir / "work", options, true).registered_images, 3);
}

}  // namespace
}  // namespace ibrdf
