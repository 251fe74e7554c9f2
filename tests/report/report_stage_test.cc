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
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/math.h"
#include "core/merl_brdf.h"
#include "core/sample_file.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/consistency.h"
#include "reconstruct/merl_table.h"
#include "reconstruct/prediction_check.h"
#include "reconstruct/reconstruction_stage.h"
#include "reconstruct/truth_comparison.h"
#include "tests/run_ibrdf.h"
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

std::string Capture(const std::string& command) { return testing::RunShell(command).output; }

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
    DerenderToFile(Session::Load(s), DerenderOptions(), samples_path);
    const std::vector<BrdfSample> samples = ReadSamples(samples_path);
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
  EXPECT_EQ(data.at("incidence_plane")[0].at("centre_abscissa_deg").size(),
            data.at("incidence_plane")[0].at("centre").at("truth").size());
  // The title is the session's name here (no recipe; not a generator's default "synth...").
  EXPECT_EQ(data.at("title"), "s");
  for (const char* figure :
       {"coverage.png", "incidence-plane.png", "reciprocity-curves.png", "timings.png", "truth-bands.png", "photo.png",
        "photo-render-reconstruction.png", "photo-render-truth.png", "photo-difference.png",
        "sphere-reconstruction.png", "sphere-truth.png", "explorer.html"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + figure)) << figure;
  }
  // A consistency figure is drawn where it is valid, and said invalid where it is not.
  const nlohmann::json consistency = ReadJsonFile(dir_ / "run/consistency.json");
  for (const char* figure : {"reciprocity", "bilateral_symmetry"}) {
    const bool valid = consistency.at(figure).at("valid");
    EXPECT_EQ(fs::exists(folder + "/" + figure + ".png"), valid) << figure;
    if (!valid) {
      EXPECT_NE(Slurp(folder + "/index.html").find("invalid: no bin had"), std::string::npos);
    }
  }
  // The reconstruction rendered at the photo's own pixels matches the photo (the truth exactly, up to
  // the camera noise of the samples).
  for (const nlohmann::json& render : data.at("photo").at("renders")) {
    const double limit = render.at("model") == "truth" ? 0.03 : 0.05;
    EXPECT_LT(render.at("median_abs_difference").get<double>(), limit) << render.dump();
  }
  // A held-out photo (by default one, the one `check --regression --held-out 1` holds out) is shown as
  // the main photo is, rendered by a regression fitted on the other photos' samples only.
  const std::vector<BrdfSample> samples = ReadSamples(dir_ / "run/samples.npy");
  const std::vector<uint32_t> held = HeldOutImages(samples, 1);
  ASSERT_EQ(held.size(), 1u);
  ASSERT_EQ(data.at("held_out").size(), 1u);
  const nlohmann::json& held_out = data.at("held_out")[0];
  ASSERT_FALSE(held_out.contains("note")) << held_out.dump();
  EXPECT_EQ(held_out.at("index"), held[0]);
  size_t own = 0;
  for (const BrdfSample& s : samples) own += s.image == held[0];
  EXPECT_EQ(held_out.at("samples").get<size_t>(), own);
  EXPECT_EQ(held_out.at("fit_samples").get<size_t>(), samples.size() - own);
  ASSERT_EQ(held_out.at("renders").size(), 2u);
  EXPECT_EQ(held_out.at("renders")[0].at("model"), "held-out");
  EXPECT_EQ(held_out.at("renders")[1].at("model"), "reconstruction");
  for (const nlohmann::json& render : held_out.at("renders")) {
    EXPECT_TRUE(fs::exists(folder + "/" + render.at("file").get<std::string>()));
    EXPECT_LT(render.at("median_abs_difference").get<double>(), 0.05) << render.dump();
  }
  ASSERT_EQ(report.held_out.size(), 1u);
  EXPECT_EQ(report.held_out[0].image, held[0]);
  EXPECT_TRUE(fs::exists(folder + "/held-out-" + std::to_string(held[0]) + "-difference.png"));
  EXPECT_NE(Slurp(folder + "/index.html").find("Held-out photos"), std::string::npos);
  // The incidence-plane curves pass through the samples' band: the median of sample / reconstruction
  // at the samples' own directions is within 2 %.
  ASSERT_EQ(report.bands.size(), 4u);
  for (const BandAgreement& band : report.bands) {
    for (int c = 0; c < 3; ++c) {
      if (band.samples < 50) continue;
      EXPECT_NEAR(band.ratio[c], 1.0, 0.02) << band.theta0_deg << " deg, channel " << c;
    }
  }
  const std::string html = Slurp(folder + "/index.html");
  // Every measurement photo (6, under the limit of 24) as a thumbnail with the sample's outline, written
  // and shown in the Acquisition section with its caption.
  const nlohmann::json& thumbnails = data.at("acquisition_thumbnails");
  EXPECT_EQ(thumbnails.at("measurement_photos"), 6);
  ASSERT_EQ(thumbnails.at("photos").size(), 6u);
  for (const nlohmann::json& thumbnail : thumbnails.at("photos")) {
    const std::string file = thumbnail.at("file");
    EXPECT_TRUE(thumbnail.at("outline").get<bool>()) << file;
    EXPECT_TRUE(fs::is_regular_file(folder + "/" + file)) << file;
    EXPECT_NE(html.find("alt=\"" + file + "\""), std::string::npos) << file;
    // Not aligned here: a photo is used where it gave samples (the last looks against the light).
    const int index = thumbnail.at("index");
    const size_t photo_samples = thumbnail.at("samples");
    const std::string caption =
        "photo " + std::to_string(index) + ": " +
        (photo_samples > 0 ? "used, " + std::to_string(photo_samples) + " samples" : "no samples");
    EXPECT_NE(html.find(caption), std::string::npos) << caption;
  }
  EXPECT_NE(html.find("All 6 measurement photos"), std::string::npos);
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

// A damaged sample file: the error names it, the plotting script (started first) is stopped, and no
// report folder or temporary is left.
TEST(ReportStage, ADamagedSampleFileStopsTheScriptAndLeavesNothing) {
  ScratchDir dir;
  std::ofstream(dir / "samples.npy") << "not a .npy file";
  std::string message;
  try {
    WriteReport(dir.str(), ReportOptions());
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(dir / "samples.npy"), std::string::npos) << message;
  EXPECT_NE(message.find("bad magic"), std::string::npos) << message;
  for (const auto& entry : fs::directory_iterator(dir.str())) {
    EXPECT_EQ(entry.path().filename(), "samples.npy") << "left behind: " << entry.path();
  }
}

TEST(ReportStage, OptionsCheckNamesTheRenderSize) {
  std::string why;
  EXPECT_TRUE(ReportOptions().Check(&why)) << why;
  ReportOptions options;
  options.render_size_px = 8;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("render_size_px"), std::string::npos) << why;
  ReportOptions angles;
  angles.angles_deg = {30, 89};
  EXPECT_FALSE(angles.Check(&why));
  EXPECT_NE(why.find("angles_deg"), std::string::npos) << why;
  ReportOptions held;
  held.held_out_photos = -1;
  EXPECT_FALSE(held.Check(&why));
  EXPECT_NE(why.find("held_out_photos"), std::string::npos) << why;
}

// `report` finds the reconstruction it is given, wherever it is, and says so when it is missing.
TEST_F(ReportTest, FindsTheReconstructionItIsGiven) {
  ASSERT_NO_FATAL_FAILURE(MakeRunFolder());
  fs::rename(dir_ / "run/reconstruction", dir_ / "elsewhere");
  // A run of a recipe (run-input.json, written by `ibrdf run` before any stage) is titled by its name.
  WriteJsonFile(dir_ / "run/run-input.json", {{"input", std::string(IBRDF_SAMPLES_DIR) + "/squash"}});
  ReportOptions options;
  options.reconstruction = dir_ / "elsewhere";
  options.explorer = false;
  options.held_out_photos = 0;
  options.angles_deg = {20, 40};
  const ReportResult report = WriteReport(dir_ / "run", options);
  EXPECT_TRUE(report.reconstruction);
  EXPECT_EQ(report.reconstruction_path, dir_ / "elsewhere/brdf.binary");
  const nlohmann::json data = ReadJsonFile(dir_ / "run/report/report-data.json");
  EXPECT_EQ(data.at("reconstruction"), dir_ / "elsewhere/brdf.binary");
  EXPECT_EQ(data.at("title"), "squash");
  EXPECT_EQ(data.at("incidence_plane").size(), 2u);
  EXPECT_EQ(data.at("incidence_plane")[1].at("theta0_deg"), 40.0);
  options.reconstruction = dir_ / "nowhere";
  options.overwrite = true;
  std::string message;
  try {
    WriteReport(dir_ / "run", options);
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(dir_ / "nowhere"), std::string::npos) << message;
}

// The explorer driven in headless Chromium: the incidence slider (set from the URL fragment, the page's
// test hook) changes the plotted curve, and the curve drawn matches the table at both angles.
TEST_F(ReportTest, ExplorerSliderChangesTheCurveAsTheTableSays) {
  ASSERT_NO_FATAL_FAILURE(MakeRunFolder());
  ReportOptions options;
  options.held_out_photos = 0;  // shown by the test above
  const ReportResult report = WriteReport(dir_ / "run", options);
  ASSERT_TRUE(report.success);
  const std::string html = Slurp(report.explorer_html);
  EXPECT_EQ(html.find("http://"), std::string::npos);  // offline: nothing fetched
  EXPECT_EQ(html.find("https://"), std::string::npos);
  const std::string chromium = Chromium();
  if (chromium.empty())
    GTEST_SKIP() << "chromium is not installed (scripts/install-deps installs it): explorer check skipped";
  const MerlTable table = ReadMerl(dir_ / "run/reconstruction/brdf.binary");
  const MerlBrdf linear(table, "brdf.binary", MerlLookup::kLinear);  // as the report reads it
  std::vector<double> first;
  for (const int theta : {15, 45}) {
    const std::string dom = Capture(chromium +
                                    " --headless --disable-gpu --no-sandbox --virtual-time-budget=10000 "
                                    "--user-data-dir=" +
                                    dir_ / "chromium" + " --dump-dom 'file://" + report.explorer_html +
                                    "#theta_i=" + std::to_string(theta) + "&phi=0&channel=1' 2>/dev/null");
    std::smatch match;
    ASSERT_TRUE(std::regex_search(dom, match, std::regex("<pre id=\"ibrdf-test\"[^>]*>([^<]*)</pre>")))
        << "no test output; DOM (first 500 characters): " << dom.substr(0, 500);
    std::string text = match[1];
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"&quot;", "\""}, {"&amp;", "&"}}) {
      for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at))
        text.replace(at, from.size(), to);
    }
    const nlohmann::json drawn = nlohmann::json::parse(text);
    EXPECT_EQ(drawn.at("theta_i"), theta);
    const nlohmann::json& values = drawn.at("curves").at("reconstruction").at("values");
    ASSERT_EQ(values.size(), 179u);
    std::vector<double> curve;
    int compared = 0;
    for (int k = 0; k < 179; ++k) {
      const int x = -89 + k;
      // The directions as the report builds them (kDegree): in the incidence plane phi_d sits on the
      // table's seam (cells 0 and 179), where the last bit of phi decides which is the reader's own cell.
      const Eigen::Vector3d wi = FromSpherical(theta * kDegree, 0.0);
      const Eigen::Vector3d wo = FromSpherical(std::abs(x) * kDegree, (x >= 0 ? 0 : 180) * kDegree);
      const Eigen::Vector3d expected = linear.Lookup(wi, wo);
      curve.push_back(values[k].is_null() ? -1.0 : values[k].get<double>());
      if (expected[1] < 0.0) {
        EXPECT_TRUE(values[k].is_null()) << x;
        continue;
      }
      ASSERT_FALSE(values[k].is_null()) << x;
      EXPECT_NEAR(values[k].get<double>(), expected[1], 1e-5 * expected[1] + 1e-7)
          << "theta_i " << theta << ", x " << x;
      ++compared;
    }
    // Enough table cells to compare: the honest table leaves the unmeasured ones at -1
    // (drawn as gaps, checked above), which at theta_i 15 leaves 93 of the 179 directions.
    EXPECT_GT(compared, 80) << theta;
    EXPECT_GT(drawn.at("samples").get<int>(), 0) << theta;
    if (first.empty()) {
      first = curve;
    } else {
      double change = 0.0;
      for (size_t k = 0; k < curve.size(); ++k) change = std::max(change, std::abs(curve[k] - first[k]));
      EXPECT_GT(change, 0.01) << "moving the slider from 15 to 45 deg did not change the curve";
    }
  }
}

}  // namespace
}  // namespace ibrdf
