// `ibrdf report`: the HTML report of a run folder opens in headless Chromium with every image shown.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using testing::RunIbrdf;
using testing::RunResult;
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

// A run folder made stage by stage (so this test does not depend on `ibrdf run`), then the report.
class ReportTest : public ::testing::Test {
 protected:
  void MakeRunFolder() {
    const std::string s = dir_ / "s", run = dir_ / "run";
    ASSERT_EQ(RunIbrdf(std::string("synth --material ") + IBRDF_SAMPLES_DIR +
                       "/materials/bluepaint.json --width 160 --height 120 --photos 6 --out " + s)
                  .exit_code,
              0);
    fs::create_directories(run);
    ASSERT_EQ(RunIbrdf("derender " + s + " --out " + run + "/samples.npy").exit_code, 0);
    ASSERT_EQ(RunIbrdf("check " + run + "/samples.npy --out " + run + "/consistency.json").exit_code, 0);
    ASSERT_EQ(RunIbrdf("compare " + run + "/samples.npy --out " + run + "/truth-comparison.json").exit_code, 0);
    ASSERT_EQ(RunIbrdf("reconstruct " + run + "/samples.npy --no-fits --out " + run + "/reconstruction --truth " + s +
                       "/truth.json")
                  .exit_code,
              0);
  }
  ScratchDir dir_;
};

TEST_F(ReportTest, WritesEveryFigureAndTheHtmlShowsThemInHeadlessChromium) {
  MakeRunFolder();
  const RunResult report = RunIbrdf("report " + dir_ / "run", true);
  ASSERT_EQ(report.exit_code, 0) << report.output;
  const std::string folder = dir_ / "run/report";
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

TEST(ReportCommand, AFolderWithoutSamplesIsOneClearLine) {
  ScratchDir dir;
  const RunResult result = RunIbrdf("report " + dir.str());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("ibrdf: error: " + dir / "samples.npy"), std::string::npos) << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

}  // namespace
}  // namespace ibrdf
