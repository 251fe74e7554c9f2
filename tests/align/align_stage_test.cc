// The align stage's own parts (align/align_stage.h): default options are valid, a COLMAP model given
// and COLMAP run at once are refused naming the constraint, and the aligned session's paths rebased
// from the input session's folder onto the output folder (photos; a mesh and its scans).
#include "align/align_stage.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/session.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;

TEST(AlignStage, DefaultOptionsAreValidAndColmapSourcesExcludeEachOther) {
  std::string why;
  AlignStageOptions options;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.colmap_model = "model";
  options.run_colmap = true;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("run_colmap"), std::string::npos) << why;
  std::string message;
  try {
    AlignSessionToFolder(Session(), options, "out");
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("align options: "), std::string::npos) << message;
}

TEST(AlignStage, RebasesPathsOntoTheOutputFolder) {
  testing::ScratchDir dir;
  Session aligned;
  aligned.directory = dir / "sessions/in";
  PhotoSpec photo;
  photo.file = "photos/a.png";
  aligned.photos = {photo};
  photo.file = dir / "elsewhere/b.png";  // absolute paths stay where they point
  aligned.photos.push_back(photo);
  aligned.sample.kind = SampleSpec::Kind::kMesh;
  aligned.sample.mesh_file = "scan/mesh.ply";
  ScanInputSpec scan;
  scan.file = "scan/view-0.ply";
  aligned.sample.scan_inputs = {scan};
  const Session rebased = aligned.Rebased(dir / "out/aligned");
  EXPECT_EQ(rebased.photos[0].file, "../../sessions/in/photos/a.png");
  EXPECT_EQ(rebased.photos[1].file, "../../elsewhere/b.png");
  EXPECT_EQ(rebased.sample.mesh_file, "../../sessions/in/scan/mesh.ply");
  EXPECT_EQ(rebased.sample.scan_inputs[0].file, "../../sessions/in/scan/view-0.ply");
  // A sphere sample has no mesh: its (unused) mesh path stays as it is.
  Session sphere;
  sphere.directory = dir / "sessions/in";
  sphere.photos = {photo};
  sphere.sample.mesh_file = "x.ply";
  const Session sphere_rebased = sphere.Rebased(dir / "out");
  EXPECT_EQ(sphere_rebased.sample.mesh_file, "x.ply");
  EXPECT_EQ(sphere_rebased.photos[0].file, "../elsewhere/b.png");
}

}  // namespace
}  // namespace ibrdf
