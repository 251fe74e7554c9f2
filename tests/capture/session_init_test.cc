// Tests of capture/session_init.h: exposures, ISO and the camera come from the photos' EXIF; bursts of
// exposures a bracket step apart become brackets and auto-exposed single photos do not; what no photo
// says is listed as missing and only a session that validates is written as session.json; photos
// without an exposure or of another size are errors naming the file.
#include "capture/session_init.h"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/session.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

// A small photo with EXIF: exposure, ISO, the focal length on a 4.5 um pixel sensor, a capture time.
std::string Photo(const ScratchDir& dir, const std::string& name, double exposure_s, double iso, int second,
                  int width = 40, int height = 30) {
  Image image(width, height, 3);
  for (float& v : image.pixels) v = 0.25f;
  PhotoMetadata m;
  m.exposure_s = exposure_s;
  m.iso = iso;
  m.f_number = 8.0;
  m.focal_length_mm = 9.0;
  m.pixels_per_mm = 1.0 / 0.0045;
  m.make = "ibrdf";
  m.model = "test";
  char time[32];
  std::snprintf(time, sizeof(time), "2026:01:01 12:%02d:%02d", second / 60, second % 60);
  m.date_time = time;
  const std::string path = dir / name;
  WriteImage(path, image, PixelFormat::kUint16, &m);
  return path;
}

// A targets file with four markers of known layout and a light card.
std::string TargetsFile(const ScratchDir& dir) {
  nlohmann::json reference = nlohmann::json::array();
  for (int id = 0; id < 4; ++id) {
    const double x = 0.1 * (id % 2 ? 1 : -1), y = 0.1 * (id / 2 ? 1 : -1), h = 0.014;
    reference.push_back(
        {{"id", id}, {"corners", {{x - h, y + h, 0}, {x + h, y + h, 0}, {x + h, y - h, 0}, {x - h, y - h, 0}}}});
  }
  const nlohmann::json targets = {
      {"targets",
       {{"dictionary", "DICT_4X4_50"},
        {"reference", reference},
        {"light", {{"size", 0.06}, {"markers", {{{"id", 20}, {"light_in_marker", {0.0, -0.08, 0.0}}}}}}}}}};
  WriteJsonFile(dir / "targets.json", targets);
  return dir / "targets.json";
}

TEST(SessionInit, DefaultOptionsNeedPhotos) {
  std::string why;
  EXPECT_FALSE(SessionInitOptions().Check(&why));
  SessionInitOptions options;
  options.photos = {"a.png"};
  EXPECT_TRUE(options.Check(&why)) << why;
  options.radius_known = true;  // without a radius
  EXPECT_FALSE(options.Check(&why));
}

// Three poses, each a burst of three exposures 2 stops apart 1 s apart, poses 10 s apart: three brackets.
// Auto-exposed single photos (10 s apart, or exposures within 1.5 x) are no brackets.
TEST(SessionInit, GroupsBurstsIntoBrackets) {
  ScratchDir dir;
  SessionInitOptions options;
  int second = 0;
  for (int pose = 0; pose < 3; ++pose) {
    for (int k = 0; k < 3; ++k) {
      options.photos.push_back(
          Photo(dir, "b" + std::to_string(pose) + std::to_string(k) + ".png", 0.1 / (1 << (2 * k)), 100, second));
      second += 1;
    }
    second += 9;
  }
  options.photos.push_back(Photo(dir, "single0.png", 0.05, 100, second += 10));
  options.photos.push_back(Photo(dir, "single1.png", 0.045, 100, second += 1));  // 1 s apart, but within 1.5 x
  options.photos.push_back(Photo(dir, "single2.png", 0.2, 100, second += 10));   // 4 x, but 10 s apart
  const SessionInitResult result = InitSession(options, dir / "out");
  ASSERT_EQ(result.photos.size(), 12u);
  EXPECT_EQ(result.brackets, 3);
  for (int pose = 0; pose < 3; ++pose) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(result.photos[3 * pose + k].bracket, result.photos[3 * pose].bracket);
    EXPECT_GE(result.photos[3 * pose].bracket, 0);
  }
  EXPECT_NE(result.photos[0].bracket, result.photos[3].bracket);
  for (int i = 9; i < 12; ++i) EXPECT_EQ(result.photos[i].bracket, -1) << result.photos[i].file;
  // A stated bracket size groups by count.
  options.photos.resize(9);
  options.bracket_size = 3;
  options.overwrite = true;
  EXPECT_EQ(InitSession(options, dir / "out").brackets, 3);
  options.bracket_size = 2;  // 9 photos are no whole number of brackets of 2
  EXPECT_THROW(InitSession(options, dir / "out"), Error);
}

// What no photo says is listed; the draft is written, session.json is not. With everything given the
// session validates: exposures and gains from EXIF, the camera from the focal length, the targets, the
// light photos' role.
TEST(SessionInit, ListsWhatIsMissingThenValidates) {
  ScratchDir dir;
  SessionInitOptions options;
  options.photos = {Photo(dir, "a.png", 0.02, 100, 0), Photo(dir, "b.png", 0.025, 200, 20)};
  const SessionInitResult draft = InitSession(options, dir / "out");
  EXPECT_FALSE(draft.complete);
  EXPECT_EQ(draft.path, dir / "out/session.draft.json");
  EXPECT_FALSE(fs::exists(dir / "out/session.json"));
  std::string missing;
  for (const std::string& line : draft.missing) missing += line + "\n";
  EXPECT_NE(missing.find("--light-position"), std::string::npos) << missing;
  EXPECT_NE(missing.find("--light-intensity"), std::string::npos) << missing;
  EXPECT_NE(missing.find("--sample-radius"), std::string::npos) << missing;
  EXPECT_NE(missing.find("--targets"), std::string::npos) << missing;
  EXPECT_EQ(ReadJsonFile(draft.path)["missing"].size(), draft.missing.size());
  EXPECT_THROW(Session::Load(draft.path), Error);  // a draft is never mistaken for a session

  options.targets_file = TargetsFile(dir);
  options.target_photos = {Photo(dir, "light.png", 0.5, 100, 100)};
  options.light_intensity = Eigen::Vector3d(1.0, 0.9, 0.8);
  options.sample_radius = 0.02;
  options.radius_known = true;
  options.overwrite = true;
  const SessionInitResult done = InitSession(options, dir / "out");
  ASSERT_TRUE(done.complete) << (done.missing.empty() ? "" : done.missing.front());
  EXPECT_FALSE(fs::exists(dir / "out/session.draft.json"));
  const Session session = Session::Load(dir / "out/session.json");
  ASSERT_EQ(session.photos.size(), 3u);
  EXPECT_NEAR(session.photos[0].exposure_s, 0.02, 1e-6);
  EXPECT_NEAR(session.photos[1].exposure_s, 0.025, 1e-6);
  EXPECT_EQ(session.photos[0].gain, 1.0);
  EXPECT_EQ(session.photos[1].gain, 2.0);  // ISO 200 over the lowest, 100
  EXPECT_EQ(session.photos[2].role, PhotoRole::kTargets);
  EXPECT_EQ(session.camera.width, 40);
  EXPECT_NEAR(session.camera.FocalX(), 9.0 / 0.0045, 0.5);
  EXPECT_EQ(session.camera.PrincipalX(), 20.0);
  EXPECT_TRUE(session.sample.radius_known);
  EXPECT_EQ(session.sample.center, Eigen::Vector3d(0.0, 0.0, 0.02));  // on the platform's centre
  ASSERT_TRUE(session.targets && session.targets->light);
  EXPECT_EQ(session.lights[0].intensity, Eigen::Vector3d(1.0, 0.9, 0.8));
  // The photos stay where they are: the manifest names them relative to the output folder.
  EXPECT_EQ(fs::path(session.PhotoPath(0)).lexically_normal(), fs::path(dir / "a.png").lexically_normal());
  // An existing session is not replaced without overwrite.
  options.overwrite = false;
  EXPECT_THROW(InitSession(options, dir / "out"), Error);
}

// White-reference photos: with the white card's markers in the targets nothing of
// its pose is drafted or missing (`ibrdf align` poses it), the light needs no intensity; without them
// its centre and normal are listed as missing, and so is its size when not given.
TEST(SessionInit, WhiteReferencePhotosNeedNoPoseWithTheCardsMarkers) {
  ScratchDir dir;
  SessionInitOptions options;
  options.photos = {Photo(dir, "a.png", 0.02, 100, 0), Photo(dir, "b.png", 0.025, 100, 20)};
  options.white_photos = {Photo(dir, "white.png", 0.004, 100, 60)};
  options.targets_file = TargetsFile(dir);
  options.sample_radius = 0.02;
  const SessionInitResult draft = InitSession(options, dir / "out");
  EXPECT_FALSE(draft.complete);
  std::string missing;
  for (const std::string& line : draft.missing) missing += line + "\n";
  EXPECT_NE(missing.find("--white-size-m"), std::string::npos) << missing;
  EXPECT_NE(missing.find("centre and normal"), std::string::npos) << missing;
  EXPECT_EQ(missing.find("--light-intensity"), std::string::npos) << missing;

  nlohmann::json targets = ReadJsonFile(options.targets_file);
  const nlohmann::json corners = {{-0.05, 0.05, 0}, {-0.03, 0.05, 0}, {-0.03, 0.03, 0}, {-0.05, 0.03, 0}};
  nlohmann::json marker = {{"id", 40}, {"corners", corners}};
  targets["targets"]["white_reference"] = {{"markers", nlohmann::json::array({marker})}};
  WriteJsonFile(options.targets_file, targets);
  options.white_size = 0.05;
  options.overwrite = true;
  const SessionInitResult done = InitSession(options, dir / "out");
  ASSERT_TRUE(done.complete) << (done.missing.empty() ? "" : done.missing.front());
  const Session session = Session::Load(done.path);
  ASSERT_EQ(session.photos.size(), 2u);  // the white photo is no measurement photo
  ASSERT_TRUE(session.calibration && session.calibration->white_reference);
  const WhiteReferenceSpec& white = *session.calibration->white_reference;
  EXPECT_FALSE(white.posed);
  ASSERT_EQ(white.photos.size(), 1u);
  EXPECT_NEAR(white.photos[0].exposure_s, 0.004, 1e-7);
  EXPECT_EQ(white.size, 0.05);
  EXPECT_EQ(white.reflectance, Eigen::Vector3d::Constant(0.99));
  EXPECT_FALSE(session.lights[0].has_intensity);
}

TEST(SessionInit, PhotoWithoutExposureIsAnErrorNamingIt) {
  ScratchDir dir;
  Image image(40, 30, 3);
  WriteImage(dir / "plain.png", image, PixelFormat::kUint16);
  SessionInitOptions options;
  options.photos = {Photo(dir, "a.png", 0.02, 100, 0), dir / "plain.png"};
  try {
    InitSession(options, dir / "out");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("plain.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exposure"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "out/session.json"));
}

// Photos without EXIF exposure: --exposure-s, one value for every such photo or one per photo (the
// manifest's order); EXIF's wins where present; stated as assumed; a wrong count is an error naming it.
TEST(SessionInit, ExposureTimesGivenWhereExifHasNone) {
  ScratchDir dir;
  Image image(40, 30, 3);
  WriteImage(dir / "plain1.png", image, PixelFormat::kUint16);
  WriteImage(dir / "plain2.png", image, PixelFormat::kUint16);
  SessionInitOptions options;
  options.photos = {dir / "plain1.png", Photo(dir, "a.png", 0.02, 100, 0), dir / "plain2.png"};
  options.exposure_s = {0.5};
  const SessionInitResult one = InitSession(options, dir / "one");
  ASSERT_TRUE(one.written);
  const nlohmann::json photos = ReadJsonFile(one.path)["photos"];
  ASSERT_EQ(photos.size(), 3u);
  EXPECT_EQ(photos[0]["exposure_s"].get<double>(), 0.5);
  EXPECT_NEAR(photos[1]["exposure_s"].get<double>(), 0.02, 1e-7);  // EXIF's
  EXPECT_EQ(photos[2]["exposure_s"].get<double>(), 0.5);
  std::string assumed;
  for (const std::string& line : one.assumptions) assumed += line + "\n";
  EXPECT_NE(assumed.find("exposure time 0.5 s (--exposure-s, as given) for 2 photo(s)"), std::string::npos) << assumed;

  options.exposure_s = {0.25, 0.3, 0.125};
  const SessionInitResult each = InitSession(options, dir / "each");
  const nlohmann::json each_photos = ReadJsonFile(each.path)["photos"];
  EXPECT_EQ(each_photos[0]["exposure_s"].get<double>(), 0.25);
  EXPECT_NEAR(each_photos[1]["exposure_s"].get<double>(), 0.02, 1e-7);
  EXPECT_EQ(each_photos[2]["exposure_s"].get<double>(), 0.125);

  options.exposure_s = {0.25, 0.125};
  try {
    InitSession(options, dir / "bad");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--exposure-s"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "bad"));
  options.exposure_s = {-1.0};
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  options.exposure_s.clear();
  try {
    InitSession(options, dir / "none");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--exposure-s"), std::string::npos) << e.what();  // the remedy
  }
}

// `ibrdf targets` writes board.json beside targets.json; given as the targets it is refused at once,
// naming the file, what it is and what to pass; nothing is written.
TEST(SessionInit, BoardFileAsTargetsIsRefused) {
  ScratchDir dir;
  const nlohmann::json board = {{"format", "ibrdf-charuco-board"}, {"version", 1}, {"dictionary", "DICT_5X5_100"},
                                {"squares_x", 9},  {"squares_y", 7}, {"square_size", 0.025}, {"marker_size", 0.018}};
  WriteJsonFile(dir / "board.json", board);
  SessionInitOptions options;
  options.photos = {Photo(dir, "a.png", 0.02, 100, 0)};
  options.targets_file = dir / "board.json";
  try {
    InitSession(options, dir / "out");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(dir / "board.json"), std::string::npos) << message;
    EXPECT_NE(message.find("ChArUco board"), std::string::npos) << message;
    EXPECT_NE(message.find("targets.json"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(SessionInit, PhotosOfAnotherSizeAreAnError) {
  ScratchDir dir;
  SessionInitOptions options;
  options.photos = {Photo(dir, "a.png", 0.02, 100, 0), Photo(dir, "big.png", 0.02, 100, 20, 80, 60)};
  try {
    InitSession(options, dir / "out");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("big.png"), std::string::npos) << e.what();
  }
}

// Without a focal-plane resolution: the 35 mm equivalent, or the sensor width given.
TEST(SessionInit, CameraFromThirtyFiveMillimetreFocal) {
  PhotoMetadata m;
  m.width = 6000;
  m.height = 4000;
  m.focal_length_35mm = 50.0;
  Camera camera;
  std::string source;
  ASSERT_TRUE(CameraFromMetadata(m, 0.0, &camera, &source));
  EXPECT_NEAR(camera.FocalX(), 50.0 * std::hypot(6000, 4000) / std::hypot(36, 24), 1e-9);  // 8333 px
  m.focal_length_35mm.reset();
  m.focal_length_mm = 35.0;
  EXPECT_FALSE(CameraFromMetadata(m, 0.0, &camera, &source));
  ASSERT_TRUE(CameraFromMetadata(m, 23.5, &camera, &source));
  EXPECT_NEAR(camera.FocalX(), 35.0 * 6000 / 23.5, 1e-9);
}

}  // namespace
}  // namespace ibrdf
