// The report stage (report/report_stage.h) through its library call: the HTML report of a run folder
// made stage by stage opens in headless Chromium with every image shown; the report data holds the
// photo, the renders and the incidence-plane curves; what is not a run folder is a clear error.
#include "report/report_stage.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/consistency.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/truth_comparison.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::ScratchDir;

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string Chromium() {
  for (const char* path : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"}) {
    if (::access(path, X_OK) == 0) return path;
  }
  return "";
}

std::string Capture(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return output;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) output.append(buffer, n);
  pclose(pipe);
  return output;
}

// A run folder made stage by stage through the libraries, as `ibrdf run` lays it out: samples.npy (with
// its sidecar), consistency.json, truth-comparison.json, reconstruction/.
class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override { SetVerbosity(0); }
  void MakeRunFolder() {
    const std::string s = dir_ / "s", run = dir_ / "run";
    SynthOptions synth;
    synth.rig.width = 160;
    synth.rig.height = 120;
    synth.rig.num_photos = 6;
    const std::unique_ptr<BrdfModel> material =
        LoadMaterial(std::string(IBRDF_SAMPLES_DIR) + "/materials/bluepaint.json");
    testing::MakeSession(s, synth, *material);
    fs::create_directories(run);
    const std::string samples_path = run + "/samples.npy";
    const std::vector<BrdfSample> samples = DerenderToFile(Session::Load(s), DerenderOptions(), samples_path).samples;
    WriteJsonFile(run + "/consistency.json", CheckSamples(samples, ConsistencyOptions(), nullptr));
    const std::string truth_path = TruthPathFromSidecar(samples_path);
    nlohmann::json comparison = ToJson(CompareWithTruth(samples, *LoadTruthMaterial(truth_path)));
    comparison["samples"] = samples_path;
    comparison["truth"] = truth_path;
    WriteJsonFile(run + "/truth-comparison.json", comparison);
    ReconstructOptions reconstruct;
    reconstruct.fits = false;
    reconstruct.truth_file = s + "/truth.json";
    ASSERT_TRUE(ReconstructFile(samples_path, reconstruct, run + "/reconstruction").success);
  }
  ScratchDir dir_;
};

TEST_F(ReportTest, WritesEveryFigureAndTheHtmlShowsThemInHeadlessChromium) {
  ASSERT_NO_FATAL_FAILURE(MakeRunFolder());
  const ReportResult report = WriteReport(dir_ / "run", ReportOptions());
  ASSERT_TRUE(report.success);
  const std::string folder = dir_ / "run/report";
  EXPECT_EQ(report.index_html, folder + "/index.html");
  EXPECT_TRUE(report.photo_shown) << report.photo_note;
  EXPECT_TRUE(report.reconstruction);
  EXPECT_TRUE(report.truth);
  const nlohmann::json data = ReadJsonFile(folder + "/report-data.json");
  EXPECT_EQ(data.at("photo").at("index"), report.photo);
  EXPECT_EQ(data.at("incidence_plane").size(), 4u);
  EXPECT_EQ(data.at("incidence_plane")[0].at("angle_deg").size(), data.at("incidence_plane")[0].at("truth").size());
  for (const char* figure : {"coverage.png", "incidence-plane.png", "reciprocity.png", "isotropy.png", "timings.png",
                             "truth-bands.png", "photo.png", "render.png", "render-truth.png"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + figure)) << figure;
  }
  const std::string html = Slurp(folder + "/index.html");
  // Self-contained: every image is embedded, none is fetched from a path.
  const int images = Count(html, "<img ");
  const int embedded = Count(html, "<img src=\"data:image/png;base64,");
  EXPECT_GE(images, 9);
  EXPECT_EQ(images, embedded);

  const std::string chromium = Chromium();
  if (chromium.empty())
    GTEST_SKIP() << "chromium is not installed (scripts/install-deps installs it): browser check skipped";
  // The page plus a script that counts the images the browser decoded, and one broken image that must
  // count as failed (so the check can fail).
  std::string page = html;
  const std::string probe =
      "<img id=\"broken\" src=\"data:image/png;base64,AAAA\">"
      "<pre id=\"result\"></pre><script>window.addEventListener('load', function() {"
      "var ok = 0, bad = 0; for (var i = 0; i < document.images.length; ++i) { var im = document.images[i];"
      "if (im.id == 'broken') continue; if (im.complete && im.naturalWidth > 0) ++ok; else ++bad; }"
      "var b = document.getElementById('broken'); var broken = b.complete && b.naturalWidth > 0 ? 'shown' : 'failed';"
      "document.getElementById('result').textContent = 'IMAGES ok=' + ok + ' bad=' + bad + ' broken=' + broken; });"
      "</script></body>";
  page.replace(page.rfind("</body>"), 7, probe);
  { std::ofstream(dir_ / "check.html") << page; }
  const std::string dom = Capture(chromium +
                                  " --headless --disable-gpu --no-sandbox --virtual-time-budget=5000 "
                                  "--user-data-dir=" +
                                  dir_ / "chromium" + " --dump-dom file://" + dir_ / "check.html" + " 2>/dev/null");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(dom, match, std::regex("IMAGES ok=(\\d+) bad=(\\d+) broken=(\\w+)")))
      << "chromium printed no result; DOM (first 500 characters): " << dom.substr(0, 500);
  EXPECT_EQ(std::stoi(match[1]), images);
  EXPECT_EQ(std::stoi(match[2]), 0);
  EXPECT_EQ(match[3], "failed");
}

TEST(ReportStage, AFolderWithoutSamplesIsAnErrorNamingThem) {
  ScratchDir dir;
  std::string message;
  try {
    WriteReport(dir.str(), ReportOptions());
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(dir / "samples.npy"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "report"));
}

TEST(ReportStage, OptionsCheckNamesTheRenderSize) {
  std::string why;
  EXPECT_TRUE(ReportOptions().Check(&why)) << why;
  ReportOptions options;
  options.render_size = 8;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("render_size"), std::string::npos) << why;
}

}  // namespace
}  // namespace ibrdf
