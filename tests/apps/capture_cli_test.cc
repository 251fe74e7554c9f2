// The capture kit through the command line: `ibrdf targets` writes the sheets and a targets
// block equal to `ibrdf synth --targets`'s layout (in the platform's frame); `ibrdf session init` on a
// synthetic capture's photos alone (their EXIF) drafts a session whose exposures are the synthetic ones,
// says what is missing with exit status 2, and validates once it is given.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/session.h"
#include "tests/run_ibrdf.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

using testing::MaterialPath;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;
namespace fs = std::filesystem;

TEST(CaptureCli, TargetsMatchTheSyntheticLayout) {
  ScratchDir dir;
  const RunResult targets = RunIbrdf("targets --out " + dir / "targets" + " --dpi 100");
  ASSERT_EQ(targets.exit_code, 0) << targets.output;
  for (const char* file :
       {"platform.svg", "platform.png", "light-card.svg", "light-card.png", "white-card.svg", "white-card.png",
        "charuco.svg", "charuco.png", "board.json", "targets.json", "README.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / ("targets/" + std::string(file)))) << file;
  }
  // The SVG states its printed size in millimetres; the PNG is that size at the DPI.
  std::ifstream svg(dir / "targets/platform.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("width=\"290.000000mm\""), std::string::npos);
  EXPECT_NE(text.find("scale bar: 100.0 mm"), std::string::npos);
  const ImageSpec png = ReadImageSpec(dir / "targets/platform.png");
  EXPECT_EQ(png.width, static_cast<int>(std::ceil(290.0 / 25.4 * 100.0)));
  // A synthetic session with targets: the same markers, shifted by the platform's height.
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + MaterialPath("lambertian50") +
                                   " --photos 1 --width 96 --height 72 --targets --light-photos 1");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Session session = Session::Load(dir / "s");
  const nlohmann::json block = ReadJsonFile(dir / "targets/targets.json")["targets"];
  ASSERT_EQ(block["reference"].size(), session.targets->reference.size());
  for (size_t i = 0; i < session.targets->reference.size(); ++i) {
    const TargetSpec& expected = session.targets->reference[i];
    EXPECT_EQ(block["reference"][i]["id"].get<int>(), expected.id);
    for (int k = 0; k < 4; ++k) {
      for (int a = 0; a < 3; ++a) {
        const double shift = a == 2 ? session.sample.radius : 0.0;  // synth's world origin: the sphere's centre
        EXPECT_NEAR(block["reference"][i]["corners"][k][a].get<double>(), expected.corners[k][a] + shift, 1e-12);
      }
    }
  }
  ASSERT_TRUE(session.targets->light);
  ASSERT_EQ(block["light"]["markers"].size(), session.targets->light->markers.size());
  EXPECT_EQ(block["light"]["size"].get<double>(), session.targets->light->size);
  for (size_t i = 0; i < session.targets->light->markers.size(); ++i) {
    const LightMarkerSpec& expected = session.targets->light->markers[i];
    EXPECT_EQ(block["light"]["markers"][i]["id"].get<int>(), expected.id);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(block["light"]["markers"][i]["light_in_marker"][a].get<double>(), expected.light_in_marker[a], 1e-12);
    }
  }
  // Markers beyond the dictionary: an error, nothing written.
  const RunResult bad = RunIbrdf("targets --out " + dir / "bad" +
                                 " --ring-count 60 --ring-radius-mm 600 --platform-radius-mm 640 --light-markers 0");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("DICT_4X4_50"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

TEST(CaptureCli, SessionInitFromSyntheticPhotos) {
  ScratchDir dir;
  const RunResult synth = RunIbrdf("synth --out " + dir / "s" + " --material " + MaterialPath("lambertian50") +
                                   " --photos 3 --brackets 2 --width 96 --height 72");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const Session truth = Session::Load(dir / "s");
  std::string photos;
  for (size_t i = 0; i < truth.photos.size(); ++i) photos += " " + truth.PhotoPath(i);
  // Nothing about the scene: exit status 2, a draft, the missing items named.
  const RunResult draft = RunIbrdf("session init" + photos + " --out " + dir / "init");
  EXPECT_EQ(draft.exit_code, 2) << draft.output;
  EXPECT_NE(draft.output.find("missing: the light's position"), std::string::npos) << draft.output;
  EXPECT_TRUE(fs::exists(dir / "init/session.draft.json"));
  EXPECT_FALSE(fs::exists(dir / "init/session.json"));
  // Given the scene (and a targets block, from which align would pose the photos): the session, with
  // the synthetic exposures and brackets read from EXIF.
  ASSERT_EQ(RunIbrdf("targets --out " + dir / "targets" + " --no-charuco --dpi 72").exit_code, 0);
  const RunResult done =
      RunIbrdf("session init" + photos + " --out " + dir / "init" + " --targets " + dir / "targets/targets.json" +
               " --light-position-m 1.2 0 0 --light-intensity 1 1 1 --sample-radius-m 0.04"
               " --sample-center-m 0 0 0 --overwrite");
  ASSERT_EQ(done.exit_code, 0) << done.output;
  const Session session = Session::Load(dir / "init/session.json");
  ASSERT_EQ(session.photos.size(), truth.photos.size());
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    EXPECT_NEAR(session.photos[i].exposure_s / truth.photos[i].exposure_s, 1.0, 1e-6) << i;
    EXPECT_EQ(session.photos[i].gain, 1.0);
    ASSERT_TRUE(session.photos[i].bracket && truth.photos[i].bracket) << i;
    EXPECT_EQ(*session.photos[i].bracket, *truth.photos[i].bracket) << i;
  }
  EXPECT_NEAR(session.camera.FocalX(), truth.camera.FocalX(), 1e-3 * truth.camera.FocalX());
  EXPECT_FALSE(session.radiometry.saturation_stated);
}

// A camera's card as synth leaves it (bluepaint sphere on the marker platform, 3 photos of the light's
// card, `synth_flags` more), printed targets, and `ibrdf session init` over the photos into DIR/s with
// `init_flags`; returns session init's result.
RunResult InitFromCard(const ScratchDir& dir, const std::string& synth_flags, const std::string& init_flags) {
  const RunResult synth = RunIbrdf("synth --out " + dir / "synth" + " --material " + MaterialPath("bluepaint") +
                                   " --targets --light-photos 3" + synth_flags);
  EXPECT_EQ(synth.exit_code, 0) << synth.output;
  const Session truth = Session::Load(dir / "synth");
  std::string photos, light_photos;
  for (size_t i = 0; i < truth.photos.size(); ++i) {
    (truth.photos[i].role == PhotoRole::kTargets ? light_photos : photos) += " " + truth.PhotoPath(i);
  }
  EXPECT_EQ(RunIbrdf("targets --out " + dir / "targets" + " --no-charuco --dpi 72").exit_code, 0);
  return RunIbrdf("session init" + photos + " --target-photos" + light_photos + " --targets " +
                  dir / "targets/targets.json" + init_flags + " --out " + dir / "s");
}

// A camera's card at 640x480 (photos with EXIF only): session init leaves the light's position
// "unknown" for align to find from the light's card, whose markers are too small there to pose any
// light photo. align stops with the verdict (what it posed, the remedy); nothing uses a placeholder.
TEST(CaptureCli, LowResolutionLightCardStopsAlignWithAVerdict) {
  ScratchDir dir;
  const RunResult init = InitFromCard(dir, " --photos 4 --width 640 --height 480",
                                      " --sample-radius-m 0.04 --radius-known --light-intensity 1,1,1");
  ASSERT_EQ(init.exit_code, 0) << init.output;
  EXPECT_NE(init.output.find("light position: unknown"), std::string::npos) << init.output;
  EXPECT_EQ(ReadJsonFile(dir / "s/session.json").at("light").at("position"), "unknown");
  const RunResult align = RunIbrdf("align " + dir / "s" + " --out " + dir / "aligned");
  EXPECT_EQ(align.exit_code, 1) << align.output;
  EXPECT_NE(align.output.find("light fit failed"), std::string::npos) << align.output;
  EXPECT_NE(align.output.find("0 of 3 light photos posed"), std::string::npos) << align.output;
  EXPECT_FALSE(fs::exists(dir / "aligned"));
  // run stops at the same place: no stage after align runs with the placeholder.
  const RunResult run = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" + " --no-report");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("light fit failed"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir / "run/samples.npy"));
}

// Two photos and a wrong radius guess (0.03 m for a 0.04 m sphere), the radius not known: the sphere
// fit collapses onto the lit limb (a radius of micrometres, the centre far off the platform). run stops
// at align with the named verdicts, the values, the bounds and the remedy; accepted by name, the run
// goes on to the uniformity check, which the wrong geometry fails too; accepted as well, the run ends
// and its summary says the failures were accepted.
TEST(CaptureCli, ACollapsedSphereFitStopsTheRunUnlessAccepted) {
  ScratchDir dir;
  const RunResult init =
      InitFromCard(dir, " --photos 2", " --sample-radius-m 0.03 --light-position-m 1.2 0 0 --light-intensity 1,1,1");
  ASSERT_EQ(init.exit_code, 0) << init.output;
  const RunResult run = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" + " --no-report --no-fits");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("sphere.radius: fail: fitted radius"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("sphere.center: fail"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("radius_known"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir / "run/align/session.json"));
  EXPECT_FALSE(fs::exists(dir / "run/samples.npy"));

  // Accepted, the wrong sphere derenders samples that disagree with each other across the surface: the
  // uniformity check, which knows nothing of align, stops the run again.
  const RunResult second = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" +
                                    " --no-fits --accept sphere.radius,sphere.center",
                                    true);
  EXPECT_EQ(second.exit_code, 1) << second.output;
  EXPECT_NE(second.output.find("uniformity.cells: fail"), std::string::npos) << second.output;
  const RunResult accepted = RunIbrdf("run " + dir / "s" + " --out " + dir / "run" +
                                      " --no-fits --accept sphere.radius,sphere.center,uniformity.cells",
                                      true);
  ASSERT_EQ(accepted.exit_code, 0) << accepted.output;
  const nlohmann::json summary = ReadJsonFile(dir / "run/summary.json");
  int accepted_failures = 0;
  for (const nlohmann::json& v : summary.at("verdicts")) {
    accepted_failures += v.at("verdict") == "fail" && v.at("accepted") == true;
  }
  EXPECT_EQ(accepted_failures, 3) << summary.dump(1);
  bool said = false;
  for (const nlohmann::json& w : summary.at("warnings")) {
    said |= w.get<std::string>().find("sphere.radius: fail (accepted by the user)") != std::string::npos;
  }
  EXPECT_TRUE(said) << summary.dump(1);
  EXPECT_NE(accepted.output.find("verdict: align sphere.radius: fail (accepted by the user)"), std::string::npos)
      << accepted.output;
  // The report opens with the verdicts and shows the acquisition: checks, photos posed, each photo with
  // the sample's outline, the sample's fit.
  std::ifstream page_file(dir / "run/report/index.html");
  const std::string page((std::istreambuf_iterator<char>(page_file)), std::istreambuf_iterator<char>());
  EXPECT_NE(page.find("<h2>Verdicts and warnings</h2>"), std::string::npos);
  EXPECT_NE(page.find("align sphere.radius: fail (accepted by the user)"), std::string::npos);
  EXPECT_NE(page.find("<h2 id=\"acquisition\">Acquisition</h2>"), std::string::npos);
  EXPECT_NE(page.find("<td>FAIL (accepted)</td>"), std::string::npos);
  EXPECT_NE(page.find("<h3>Photos posed</h3>"), std::string::npos);
  EXPECT_NE(page.find("<h3>The sample in each photo</h3>"), std::string::npos);
  EXPECT_NE(page.find("alt=\"acquisition/000.png\""), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
