// Tests of core/session.h: a session folder loads into its fields, every kind of bad manifest is an
// Error naming the manifest and the field's JSON pointer, and the manifest round-trips through ToJson.
#include "core/session.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

using nlohmann::json;

constexpr int kWidth = 8, kHeight = 6;

// A valid manifest naming two small photos; tests break one field at a time.
json ValidManifest() {
  return json::parse(R"({
    "format": "ibrdf-session",
    "version": 1,
    "name": "unit-sphere",
    "description": "a session written by session_test",
    "camera": {"model": "OPENCV", "width": 8, "height": 6,
               "params": [10.0, 11.0, 4.0, 3.0, -0.08, 0.02, 0.0005, -0.0003]},
    "light": {"kind": "point", "position": [0.1, 0.2, 1.5], "intensity": [1.0, 2.0, 3.0]},
    "sample": {"kind": "sphere", "center": [0.0, 0.0, 0.25], "radius": 0.05},
    "radiometry": {"response": "srgb", "black_level": 0.01, "saturation_level": 0.98,
                   "noise": {"full_well_e": 30000.0, "read_noise_e": 3.5, "bits": 16}},
    "photos": [
      {"file": "photos/img0.png", "exposure_s": 0.5, "gain": 2.0,
       "camera_from_world": {"rotation": [0.5, 0.5, 0.5, 0.5], "translation": [0.0, 0.1, 2.0]}},
      {"file": "photos/img1.png", "exposure_s": 0.125}
    ]
  })");
}

// A fresh session folder per test, with the two photos of ValidManifest().
class SessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch_.str();
    fs::create_directories(fs::path(dir_) / "photos");
    Image photo(kWidth, kHeight, 3);
    for (size_t i = 0; i < photo.pixels.size(); ++i) photo.pixels[i] = float(i % 7) / 7.0f;
    WriteImage(Path("photos/img0.png"), photo, PixelFormat::kUint8);
    WriteImage(Path("photos/img1.png"), photo, PixelFormat::kUint8);
  }
  testing::ScratchDir scratch_;

  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }
  std::string ManifestPath() const { return Path("session.json"); }

  void WriteManifest(const json& manifest) const { std::ofstream(ManifestPath()) << manifest.dump(2); }

  // Writes `manifest` and expects Load to throw an Error naming the manifest and `pointer`.
  void ExpectLoadError(const json& manifest, const std::string& pointer) const {
    WriteManifest(manifest);
    try {
      Session::Load(ManifestPath());
      ADD_FAILURE() << "expected an Error naming " << pointer;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(ManifestPath()), std::string::npos) << message;
      EXPECT_NE(message.find(pointer), std::string::npos) << message;
    }
  }

  std::string dir_;
};

// Every field of a valid manifest arrives where it belongs.
TEST_F(SessionTest, LoadsValidSession) {
  WriteManifest(ValidManifest());
  const Session session = Session::Load(ManifestPath());
  EXPECT_EQ(session.name, "unit-sphere");
  EXPECT_EQ(session.manifest_path, ManifestPath());
  EXPECT_TRUE(fs::equivalent(session.directory, dir_));

  EXPECT_EQ(session.camera.model, CameraModelId::kOpenCV);
  EXPECT_EQ(session.camera.width, kWidth);
  EXPECT_EQ(session.camera.height, kHeight);
  EXPECT_EQ(session.camera.params, (std::vector<double>{10.0, 11.0, 4.0, 3.0, -0.08, 0.02, 0.0005, -0.0003}));

  EXPECT_EQ(session.lights[0].kind, Light::Kind::kPoint);
  EXPECT_EQ(session.lights[0].position, Eigen::Vector3d(0.1, 0.2, 1.5));
  EXPECT_EQ(session.lights[0].intensity, Eigen::Vector3d(1.0, 2.0, 3.0));

  EXPECT_EQ(session.sample.kind, SampleSpec::Kind::kSphere);
  EXPECT_EQ(session.sample.center, Eigen::Vector3d(0.0, 0.0, 0.25));
  EXPECT_EQ(session.sample.radius, 0.05);

  EXPECT_EQ(session.radiometry.response.kind, Response::Kind::kSrgb);
  EXPECT_EQ(session.radiometry.black_level, 0.01);
  EXPECT_EQ(session.radiometry.saturation_level, 0.98);
  ASSERT_TRUE(session.radiometry.noise.has_value());
  EXPECT_EQ(session.radiometry.noise->full_well_e, 30000.0);
  EXPECT_EQ(session.radiometry.noise->read_noise_e, 3.5);
  EXPECT_EQ(session.radiometry.noise->bits, 16);

  ASSERT_EQ(session.photos.size(), 2u);
  EXPECT_EQ(session.photos[0].file, "photos/img0.png");
  EXPECT_EQ(session.photos[0].exposure_s, 0.5);
  EXPECT_EQ(session.photos[0].gain, 2.0);
  ASSERT_TRUE(session.photos[0].camera_from_world.has_value());
  const Rigid3d& pose = *session.photos[0].camera_from_world;
  EXPECT_NEAR(pose.rotation.w(), 0.5, 1e-15);
  EXPECT_NEAR(pose.rotation.x(), 0.5, 1e-15);  // [qw, qx, qy, qz] order
  EXPECT_EQ(pose.translation, Eigen::Vector3d(0.0, 0.1, 2.0));
  EXPECT_EQ(session.photos[1].exposure_s, 0.125);
  EXPECT_EQ(session.photos[1].gain, 1.0);  // the default
  EXPECT_FALSE(session.photos[1].camera_from_world.has_value());

  // Photo paths resolve against the session folder.
  EXPECT_TRUE(fs::equivalent(session.PhotoPath(1), Path("photos/img1.png")));
  EXPECT_NO_THROW(session.CheckPhotos());
}

// Load accepts the folder as well as the manifest path.
TEST_F(SessionTest, LoadsFromFolder) {
  WriteManifest(ValidManifest());
  const Session session = Session::Load(dir_);
  EXPECT_TRUE(fs::equivalent(session.manifest_path, ManifestPath()));
  EXPECT_EQ(session.photos.size(), 2u);
  EXPECT_TRUE(fs::is_regular_file(session.PhotoPath(0)));
}

// Minimal manifest: optional blocks absent take their defaults (linear response, no noise model).
TEST_F(SessionTest, OptionalBlocksTakeDefaults) {
  json manifest = ValidManifest();
  manifest.erase("radiometry");
  manifest.erase("name");
  manifest.erase("description");
  WriteManifest(manifest);
  const Session session = Session::Load(ManifestPath());
  EXPECT_EQ(session.radiometry.response.kind, Response::Kind::kLinear);
  EXPECT_EQ(session.radiometry.black_level, 0.0);
  EXPECT_EQ(session.radiometry.saturation_level, 1.0);
  EXPECT_FALSE(session.radiometry.noise.has_value());
  EXPECT_FALSE(session.name.empty());  // the folder's name
}

// stages_applied: the calibration stages that wrote the session round-trip in order; a name that is
// not a stage, or one listed twice, is an error naming its entry.
TEST_F(SessionTest, StagesAppliedRoundTripAndBadNamesAreErrors) {
  json manifest = ValidManifest();
  manifest["stages_applied"] = {"scan", "align"};
  WriteManifest(manifest);
  Session session = Session::Load(ManifestPath());
  EXPECT_TRUE(session.Applied(SessionStage::kAlign));
  EXPECT_FALSE(session.Applied(SessionStage::kColour));
  session.MarkApplied(SessionStage::kColour);
  session.MarkApplied(SessionStage::kAlign);  // already there: not listed twice
  EXPECT_EQ(session.ToJson()["stages_applied"], json({"scan", "align", "colour"}));
  manifest.erase("stages_applied");
  WriteManifest(manifest);
  EXPECT_FALSE(Session::Load(ManifestPath()).ToJson().contains("stages_applied"));  // absent: not written
  manifest["stages_applied"] = {"align", "derender"};
  ExpectLoadError(manifest, "/stages_applied/1");
  manifest["stages_applied"] = {"align", "align"};
  ExpectLoadError(manifest, "/stages_applied/1");
  manifest["stages_applied"] = "align";
  ExpectLoadError(manifest, "/stages_applied");
}

TEST_F(SessionTest, UnknownKeyAtRootIsAnError) {
  json manifest = ValidManifest();
  manifest["photo"] = json::array();
  ExpectLoadError(manifest, "/photo");
}

TEST_F(SessionTest, UnknownNestedKeyIsAnError) {
  json manifest = ValidManifest();
  manifest["light"]["intensty"] = {1.0, 1.0, 1.0};
  ExpectLoadError(manifest, "/light/intensty");
  manifest = ValidManifest();
  manifest["photos"][1]["exposure"] = 0.1;
  ExpectLoadError(manifest, "/photos/1/exposure");
  manifest = ValidManifest();
  manifest["radiometry"]["noise"]["bitz"] = 12;
  ExpectLoadError(manifest, "/radiometry/noise/bitz");
  manifest = ValidManifest();
  manifest["photos"][0]["camera_from_world"]["scale"] = 1.0;
  ExpectLoadError(manifest, "/photos/0/camera_from_world/scale");
}

TEST_F(SessionTest, MissingPhotoIsAnError) {
  json manifest = ValidManifest();
  manifest["photos"][1]["file"] = "photos/img2.png";
  ExpectLoadError(manifest, "/photos/1/file");
}

TEST_F(SessionTest, NonPositiveExposureIsAnError) {
  json manifest = ValidManifest();
  manifest["photos"][0]["exposure_s"] = -0.5;
  ExpectLoadError(manifest, "/photos/0/exposure_s");
  manifest["photos"][0]["exposure_s"] = 0.0;
  ExpectLoadError(manifest, "/photos/0/exposure_s");
  manifest = ValidManifest();
  manifest["photos"][1]["gain"] = 0.0;
  ExpectLoadError(manifest, "/photos/1/gain");
}

TEST_F(SessionTest, WrongTypeIsAnError) {
  json manifest = ValidManifest();
  manifest["sample"]["radius"] = "0.05";
  ExpectLoadError(manifest, "/sample/radius");
  manifest = ValidManifest();
  manifest["camera"]["width"] = 8.5;
  ExpectLoadError(manifest, "/camera/width");
  manifest = ValidManifest();
  manifest["light"]["position"] = {0.0, 1.0};
  ExpectLoadError(manifest, "/light/position");
  manifest = ValidManifest();
  manifest["photos"] = {{"file", "photos/img0.png"}};
  ExpectLoadError(manifest, "/photos");
}

TEST_F(SessionTest, NonUnitQuaternionIsAnError) {
  json manifest = ValidManifest();
  manifest["photos"][0]["camera_from_world"]["rotation"] = {1.0, 0.1, 0.0, 0.0};
  ExpectLoadError(manifest, "/photos/0/camera_from_world/rotation");
  manifest["photos"][0]["camera_from_world"]["rotation"] = {1.0, 0.0, 0.0};
  ExpectLoadError(manifest, "/photos/0/camera_from_world/rotation");
}

TEST_F(SessionTest, UnsupportedCameraModelIsAnError) {
  json manifest = ValidManifest();
  manifest["camera"]["model"] = "FISHEYE";
  ExpectLoadError(manifest, "/camera/model");
}

// Camera parameters that do not fit the model name the camera block.
TEST_F(SessionTest, InvalidCameraParamsAreAnError) {
  json manifest = ValidManifest();
  manifest["camera"]["params"] = {10.0, 11.0, 4.0, 3.0};
  ExpectLoadError(manifest, "/camera");
  manifest = ValidManifest();
  manifest["camera"]["params"][0] = -10.0;
  ExpectLoadError(manifest, "/camera");
}

// The header fields: the format name and the version this ibrdf reads.
TEST_F(SessionTest, WrongFormatOrVersionIsAnError) {
  json manifest = ValidManifest();
  manifest["format"] = "colmap";
  ExpectLoadError(manifest, "/format");
  manifest = ValidManifest();
  manifest["version"] = 3;
  ExpectLoadError(manifest, "/version");
}

// Impossible values elsewhere in the manifest.
TEST_F(SessionTest, ImpossibleValuesAreErrors) {
  json manifest = ValidManifest();
  manifest["photos"] = json::array();
  ExpectLoadError(manifest, "/photos");
  manifest = ValidManifest();
  manifest["sample"]["radius"] = 0.0;
  ExpectLoadError(manifest, "/sample/radius");
  manifest = ValidManifest();
  manifest["light"]["intensity"] = {0.0, 0.0, 0.0};
  ExpectLoadError(manifest, "/light/intensity");
  manifest = ValidManifest();
  manifest["light"]["kind"] = "area";
  ExpectLoadError(manifest, "/light/kind");
  manifest = ValidManifest();
  manifest["sample"]["kind"] = "cube";
  ExpectLoadError(manifest, "/sample/kind");
  manifest = ValidManifest();
  manifest["radiometry"]["saturation_level"] = 0.005;
  ExpectLoadError(manifest, "/radiometry/saturation_level");
  manifest = ValidManifest();
  manifest["radiometry"]["response"] = {{"table", {0.0, 0.5, 0.4, 1.0}}};
  ExpectLoadError(manifest, "/radiometry/response");
  manifest = ValidManifest();
  manifest["radiometry"]["response"] = "log";
  ExpectLoadError(manifest, "/radiometry/response");
  manifest = ValidManifest();
  manifest["radiometry"]["noise"]["bits"] = 40;
  ExpectLoadError(manifest, "/radiometry/noise/bits");
}

TEST_F(SessionTest, MissingOrMalformedManifestIsAnError) {
  EXPECT_THROW(Session::Load(ManifestPath()), Error);  // not written yet
  std::ofstream(ManifestPath()) << "{\n  \"format\": \"ibrdf-session\",\n  \"version\": 1,,\n}\n";
  try {
    Session::Load(ManifestPath());
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(ManifestPath() + ":3"), std::string::npos) << e.what();
  }
}

// CheckPhotos opens every photo and names the one whose size disagrees with the camera.
TEST_F(SessionTest, CheckPhotosNamesPhotoOfWrongSize) {
  WriteImage(Path("photos/img1.png"), Image(kWidth + 1, kHeight, 3), PixelFormat::kUint8);
  WriteManifest(ValidManifest());
  const Session session = Session::Load(ManifestPath());
  try {
    session.CheckPhotos();
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("img1.png"), std::string::npos) << message;
    EXPECT_EQ(message.find("img0.png"), std::string::npos) << message;
  }
}

// A photo with two channels is neither grey nor RGB.
TEST_F(SessionTest, CheckPhotosRejectsTwoChannelPhoto) {
  WriteImage(Path("photos/img0.png"), Image(kWidth, kHeight, 2), PixelFormat::kUint8);
  WriteManifest(ValidManifest());
  const Session session = Session::Load(ManifestPath());
  EXPECT_THROW(session.CheckPhotos(), Error);
}

// Expects two sessions to have equal manifest fields.
void ExpectSameFields(const Session& a, const Session& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.camera.model, b.camera.model);
  EXPECT_EQ(a.camera.width, b.camera.width);
  EXPECT_EQ(a.camera.height, b.camera.height);
  EXPECT_EQ(a.camera.params, b.camera.params);
  EXPECT_EQ(a.lights[0].kind, b.lights[0].kind);
  EXPECT_EQ(a.lights[0].position, b.lights[0].position);
  EXPECT_LT((a.lights[0].direction - b.lights[0].direction).norm(), 1e-15);
  EXPECT_EQ(a.lights[0].intensity, b.lights[0].intensity);
  EXPECT_EQ(a.sample.kind, b.sample.kind);
  EXPECT_EQ(a.sample.center, b.sample.center);
  EXPECT_EQ(a.sample.radius, b.sample.radius);
  EXPECT_LT((a.sample.axis - b.sample.axis).norm(), 1e-15);
  EXPECT_EQ(a.sample.length, b.sample.length);
  EXPECT_EQ(a.sample.mesh_file, b.sample.mesh_file);
  EXPECT_EQ(a.radiometry.response.kind, b.radiometry.response.kind);
  EXPECT_EQ(a.radiometry.response.gamma, b.radiometry.response.gamma);
  EXPECT_EQ(a.radiometry.response.table, b.radiometry.response.table);
  EXPECT_EQ(a.radiometry.black_level, b.radiometry.black_level);
  EXPECT_EQ(a.radiometry.saturation_level, b.radiometry.saturation_level);
  ASSERT_EQ(a.radiometry.noise.has_value(), b.radiometry.noise.has_value());
  if (a.radiometry.noise) {
    EXPECT_EQ(a.radiometry.noise->full_well_e, b.radiometry.noise->full_well_e);
    EXPECT_EQ(a.radiometry.noise->read_noise_e, b.radiometry.noise->read_noise_e);
    EXPECT_EQ(a.radiometry.noise->bits, b.radiometry.noise->bits);
  }
  ASSERT_EQ(a.photos.size(), b.photos.size());
  for (size_t i = 0; i < a.photos.size(); ++i) {
    EXPECT_EQ(a.photos[i].file, b.photos[i].file);
    EXPECT_EQ(a.photos[i].exposure_s, b.photos[i].exposure_s);
    EXPECT_EQ(a.photos[i].gain, b.photos[i].gain);
    ASSERT_EQ(a.photos[i].camera_from_world.has_value(), b.photos[i].camera_from_world.has_value());
    if (a.photos[i].camera_from_world) {
      const Rigid3d& pa = *a.photos[i].camera_from_world;
      const Rigid3d& pb = *b.photos[i].camera_from_world;
      EXPECT_LT((pa.rotation.coeffs() - pb.rotation.coeffs()).norm(), 1e-15);
      EXPECT_EQ(pa.translation, pb.translation);
    }
  }
}

// Load(Save(s)) gives back the same fields, and ToJson is stable under the round trip.
TEST_F(SessionTest, SaveLoadRoundTrip) {
  WriteManifest(ValidManifest());
  const Session original = Session::Load(ManifestPath());
  const std::string copy_path = Path("copy.json");
  original.Save(copy_path);
  const Session copy = Session::Load(copy_path);
  ExpectSameFields(original, copy);
  EXPECT_EQ(copy.ToJson(), original.ToJson());
}

// The other variants round-trip too: a cylinder, a directional light, gamma and table responses.
TEST_F(SessionTest, SaveLoadRoundTripOfVariants) {
  json manifest = ValidManifest();
  manifest["light"] = {{"kind", "directional"}, {"direction", {0.0, 0.6, 0.8}}, {"intensity", {2.0, 2.0, 2.0}}};
  manifest["sample"] = {
      {"kind", "cylinder"}, {"center", {0.0, 0.0, 0.1}}, {"axis", {0.0, 0.0, 1.0}}, {"radius", 0.02}, {"length", 0.1}};
  manifest["radiometry"] = {{"response", {{"gamma", 1.8}}}};
  WriteManifest(manifest);
  const Session gamma = Session::Load(ManifestPath());
  EXPECT_EQ(gamma.lights[0].kind, Light::Kind::kDirectional);
  EXPECT_EQ(gamma.sample.kind, SampleSpec::Kind::kCylinder);
  EXPECT_EQ(gamma.radiometry.response.kind, Response::Kind::kGamma);
  gamma.Save(Path("gamma.json"));
  ExpectSameFields(gamma, Session::Load(Path("gamma.json")));

  manifest["radiometry"] = {{"response", {{"table", {0.0, 0.2, 0.5, 1.0}}}}};
  manifest["sample"] = {{"kind", "mesh"}, {"file", "scan.ply"}};
  WriteManifest(manifest);
  const Session table = Session::Load(ManifestPath());
  EXPECT_EQ(table.radiometry.response.table, (std::vector<double>{0.0, 0.2, 0.5, 1.0}));
  EXPECT_EQ(table.sample.mesh_file, "scan.ply");
  table.Save(Path("table.json"));
  ExpectSameFields(table, Session::Load(Path("table.json")));
}

// A manifest that references every kind of file: photos, a flat field, white-reference photos, and a
// mesh with raw scans (the mesh itself not written yet, as before the scan stage).
json ManifestWithEveryFile() {
  json manifest = ValidManifest();
  manifest["radiometry"]["flat_field"] = "calibration/flat.exr";
  manifest["calibration"] = {{"white_reference",
                              {{"reflectance", {0.9, 0.9, 0.9}},
                               {"center", {0.0, 0.0, 0.0}},
                               {"normal", {0.0, 0.0, 1.0}},
                               {"size", 0.1},
                               {"photos", {{{"file", "calibration/white.png"}, {"exposure_s", 0.25}}}}}}};
  const json view1 = {{"file", "scan/view-1.ply"},
                      {"world_from_scan", {{"rotation", {1.0, 0.0, 0.0, 0.0}}, {"translation", {0.0, 0.0, 0.1}}}}};
  manifest["sample"] = {{"kind", "mesh"}, {"file", "scan/mesh.ply"}, {"scan_inputs", {"scan/view-0.ply", view1}}};
  return manifest;
}

class SessionFilesTest : public SessionTest {
 protected:
  void SetUp() override {
    SessionTest::SetUp();
    fs::create_directories(Path("calibration"));
    fs::create_directories(Path("scan"));
    WriteImage(Path("calibration/flat.exr"), Image(kWidth, kHeight, 3), PixelFormat::kFloat);
    WriteImage(Path("calibration/white.png"), Image(kWidth, kHeight, 3), PixelFormat::kUint8);
    std::ofstream(Path("scan/view-0.ply")) << "ply\n";
    std::ofstream(Path("scan/view-1.ply")) << "ply\n";
    WriteManifest(ManifestWithEveryFile());
  }
  std::string Absolute(const std::string& name) const { return fs::absolute(Path(name)).lexically_normal().string(); }
};

// InputFiles lists every referenced file, absolute, in manifest order; not the manifest itself.
TEST_F(SessionFilesTest, InputFilesNamesEveryReferencedFile) {
  const Session session = Session::Load(ManifestPath());
  const std::vector<std::string> expected = {Absolute("photos/img0.png"),      Absolute("photos/img1.png"),
                                             Absolute("calibration/flat.exr"), Absolute("calibration/white.png"),
                                             Absolute("scan/mesh.ply"),        Absolute("scan/view-0.ply"),
                                             Absolute("scan/view-1.ply")};
  EXPECT_EQ(session.InputFiles(), expected);

  // A sphere session: only its photos.
  WriteManifest(ValidManifest());
  const std::vector<std::string> photos = {Absolute("photos/img0.png"), Absolute("photos/img1.png")};
  EXPECT_EQ(Session::Load(ManifestPath()).InputFiles(), photos);
}

// SaveRebased into another folder: every path field names the same file from there, by field; the
// rebased manifest loads (its photos and flat field found) and lists the same input files.
TEST_F(SessionFilesTest, SaveRebasedRewritesEveryPathFieldRelativeToTheNewFolder) {
  const Session session = Session::Load(ManifestPath());
  fs::create_directories(Path("runs/one"));
  const std::string written = session.SaveRebased(Path("runs/one"));
  EXPECT_EQ(written, Absolute("runs/one/session.json"));
  const Session rebased = Session::Load(written);
  EXPECT_EQ(rebased.photos[0].file, "../../photos/img0.png");
  EXPECT_EQ(rebased.radiometry.flat_field, "../../calibration/flat.exr");
  EXPECT_EQ(rebased.calibration->white_reference->photos[0].file, "../../calibration/white.png");
  EXPECT_EQ(rebased.sample.mesh_file, "../../scan/mesh.ply");
  ASSERT_EQ(rebased.sample.scan_inputs.size(), 2u);
  EXPECT_EQ(rebased.sample.scan_inputs[1].file, "../../scan/view-1.ply");
  EXPECT_TRUE(rebased.sample.scan_inputs[1].world_from_scan.has_value());
  EXPECT_EQ(rebased.InputFiles(), session.InputFiles());
  // Nothing but path fields changes.
  json original = session.ToJson(), moved = rebased.ToJson();
  for (json* j : {&original, &moved}) {
    for (json& photo : (*j)["photos"]) photo.erase("file");
    (*j)["radiometry"].erase("flat_field");
    (*j)["calibration"]["white_reference"]["photos"][0].erase("file");
    (*j)["sample"].erase("file");
    for (json& input : (*j)["sample"]["scan_inputs"]) {
      if (input.is_string())
        input = "";
      else
        input.erase("file");
    }
  }
  EXPECT_EQ(moved, original);
}

// With PathStyle::kAbsolute every path field is absolute; Rebased alone writes nothing and can be
// saved under another name (a temporary folder that becomes `dir`).
TEST_F(SessionFilesTest, RebasedAbsoluteAndSavedElsewhere) {
  const Session session = Session::Load(ManifestPath());
  fs::create_directories(Path("out"));
  session.SaveRebased(Path("out"), Session::PathStyle::kAbsolute);
  const Session absolute = Session::Load(Path("out/session.json"));
  EXPECT_EQ(absolute.photos[1].file, Absolute("photos/img1.png"));
  EXPECT_EQ(absolute.radiometry.flat_field, Absolute("calibration/flat.exr"));
  EXPECT_EQ(absolute.sample.scan_inputs[0].file, Absolute("scan/view-0.ply"));
  EXPECT_EQ(absolute.InputFiles(), session.InputFiles());

  const Session rebased = session.Rebased(Path("final"));
  EXPECT_FALSE(fs::exists(Path("final")));
  EXPECT_EQ(rebased.directory, Absolute("final"));
  EXPECT_EQ(rebased.photos[0].file, "../photos/img0.png");
  fs::create_directories(Path("staging"));
  rebased.Save(Path("staging/session.json"));
  fs::rename(Path("staging"), Path("final"));
  EXPECT_EQ(Session::Load(Path("final")).InputFiles(), session.InputFiles());
}

TEST(SampleKindName, NamesEveryKind) {
  EXPECT_STREQ(SampleKindName(SampleSpec::Kind::kSphere), "sphere");
  EXPECT_STREQ(SampleKindName(SampleSpec::Kind::kCylinder), "cylinder");
  EXPECT_STREQ(SampleKindName(SampleSpec::Kind::kMesh), "mesh");
  EXPECT_THROW(SampleKindName(static_cast<SampleSpec::Kind>(99)), InternalError);
  EXPECT_FALSE(IsMeshSample(SampleSpec::Kind::kSphere));
  EXPECT_FALSE(IsMeshSample(SampleSpec::Kind::kCylinder));
  EXPECT_TRUE(IsMeshSample(SampleSpec::Kind::kMesh));
}

// ---- Version 2: several lights, a light per photo, masks.

// A version-2 manifest with three lights (a point light, a directional one, one without an
// intensity that a white reference measures), each photo naming its light, and masks.
json ManifestV2() {
  json manifest = ValidManifest();
  manifest["version"] = 2;
  manifest.erase("light");
  manifest["lights"] = json::parse(R"([
    {"id": "L01", "kind": "point", "position": [0.1, 0.2, 1.5], "intensity": [1.0, 2.0, 3.0]},
    {"id": "L02", "kind": "directional", "direction": [0.0, 0.0, 2.0], "intensity": [0.5, 0.5, 0.5]},
    {"id": "L03", "kind": "point", "position": [-1.0, 0.0, 1.0]}
  ])");
  manifest["photos"][0]["light"] = "L02";
  manifest["photos"][1]["light"] = "L01";
  manifest["mask"] = "masks/all.png";
  manifest["photos"][0]["mask"] = "masks/img0.png";
  manifest["calibration"] = {{"white_reference",
                              {{"reflectance", {0.9, 0.9, 0.9}},
                               {"center", {0.0, 0.0, 0.0}},
                               {"normal", {0.0, 0.0, 1.0}},
                               {"size", 0.1},
                               {"photos", {{{"file", "photos/img1.png"}, {"exposure_s", 0.25}, {"light", "L03"}}}}}}};
  return manifest;
}

class SessionV2Test : public SessionTest {
 protected:
  void SetUp() override {
    SessionTest::SetUp();
    fs::create_directories(Path("masks"));
    Image mask(kWidth, kHeight, 1);
    WriteImage(Path("masks/all.png"), mask, PixelFormat::kUint8);
    WriteImage(Path("masks/img0.png"), mask, PixelFormat::kUint8);
  }
};

TEST_F(SessionV2Test, LoadsLightsPhotoLightsAndMasks) {
  WriteManifest(ManifestV2());
  const Session session = Session::Load(ManifestPath());
  ASSERT_EQ(session.lights.size(), 3u);
  EXPECT_EQ(session.lights[0].id, "L01");
  EXPECT_EQ(session.lights[1].kind, Light::Kind::kDirectional);
  EXPECT_EQ(session.lights[1].direction, Eigen::Vector3d::UnitZ());  // normalized on reading
  EXPECT_TRUE(session.lights[1].has_intensity);
  EXPECT_FALSE(session.lights[2].has_intensity);
  EXPECT_EQ(session.LightIndex("L03"), 2);
  EXPECT_EQ(session.LightIndex("L99"), -1);
  EXPECT_EQ(session.photos[0].light, 1u);
  EXPECT_EQ(session.photos[1].light, 0u);
  EXPECT_EQ(&session.PhotoLight(0), &session.lights[1]);
  EXPECT_EQ(session.calibration->white_reference->photos[0].light, 2u);
  EXPECT_EQ(session.mask, "masks/all.png");
  EXPECT_EQ(session.photos[0].mask, "masks/img0.png");
  EXPECT_EQ(session.PhotoMaskPath(0), Path("masks/img0.png"));
  EXPECT_EQ(session.PhotoMaskPath(1), Path("masks/all.png"));  // the session's default
  session.CheckPhotos();
  // Masks are inputs (the workflow's staleness rule sees them).
  const std::vector<std::string> files = session.InputFiles();
  EXPECT_NE(std::find(files.begin(), files.end(), fs::absolute(Path("masks/img0.png")).lexically_normal().string()),
            files.end());
  EXPECT_NE(std::find(files.begin(), files.end(), fs::absolute(Path("masks/all.png")).lexically_normal().string()),
            files.end());
}

// A version-2 manifest round-trips: lights, ids, the missing intensity, photo lights and masks.
TEST_F(SessionV2Test, SaveLoadRoundTrip) {
  WriteManifest(ManifestV2());
  const Session original = Session::Load(ManifestPath());
  fs::create_directories(Path("copy"));
  const Session copy = Session::Load(original.SaveRebased(Path("copy")));
  ASSERT_EQ(copy.lights.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(copy.lights[k].id, original.lights[k].id);
    EXPECT_EQ(copy.lights[k].kind, original.lights[k].kind);
    EXPECT_EQ(copy.lights[k].has_intensity, original.lights[k].has_intensity);
  }
  EXPECT_EQ(copy.photos[0].light, 1u);
  EXPECT_TRUE(fs::equivalent(copy.PhotoMaskPath(0), Path("masks/img0.png")));
  EXPECT_TRUE(fs::equivalent(copy.PhotoMaskPath(1), Path("masks/all.png")));
  EXPECT_EQ(copy.calibration->white_reference->photos[0].light, 2u);
  EXPECT_EQ(copy.ToJson()["version"], 2);
}

// Version 1 still reads, unchanged: the one light, photos without a light.
TEST_F(SessionV2Test, VersionOneStillReads) {
  WriteManifest(ValidManifest());
  const Session session = Session::Load(ManifestPath());
  ASSERT_EQ(session.lights.size(), 1u);
  EXPECT_TRUE(session.lights[0].id.empty());
  EXPECT_EQ(session.photos[1].light, 0u);
  EXPECT_TRUE(session.PhotoMaskPath(0).empty());
  // Written back as version 2 with the `light` shorthand, photos naming no light.
  const json written = session.ToJson();
  EXPECT_EQ(written["version"], 2);
  EXPECT_TRUE(written.contains("light"));
  EXPECT_FALSE(written.contains("lights"));
  EXPECT_FALSE(written["photos"][0].contains("light"));
}

// Version-2 keys in a version-1 manifest are errors that say which version they need.
TEST_F(SessionV2Test, VersionTwoKeysNeedVersionTwo) {
  json manifest = ValidManifest();
  manifest["photos"][0]["light"] = "L01";
  WriteManifest(manifest);
  EXPECT_NE(testing::ErrorOf([&] { Session::Load(ManifestPath()); }).find("version\": 2"), std::string::npos);
  manifest = ValidManifest();
  manifest["photos"][0]["mask"] = "masks/img0.png";
  ExpectLoadError(manifest, "/photos/0/mask");
  manifest = ValidManifest();
  manifest["lights"] = json::array();
  ExpectLoadError(manifest, "lights");
}

// The single `light` stays as the version-2 shorthand for one light.
TEST_F(SessionV2Test, SingleLightShorthand) {
  json manifest = ValidManifest();
  manifest["version"] = 2;
  WriteManifest(manifest);
  EXPECT_EQ(Session::Load(ManifestPath()).lights.size(), 1u);
  manifest["light"]["id"] = "key";
  manifest["photos"][0]["light"] = "key";
  WriteManifest(manifest);
  const Session named = Session::Load(ManifestPath());
  EXPECT_EQ(named.lights[0].id, "key");
  EXPECT_EQ(named.ToJson()["photos"][0]["light"], "key");
  // Naming a light the shorthand does not call so.
  manifest["photos"][0]["light"] = "other";
  ExpectLoadError(manifest, "/photos/0/light");
}

// Bad input: a photo naming an unknown light is one clear error naming the photo, the id and the
// lights there are.
TEST_F(SessionV2Test, PhotoNamingAnUnknownLightIsAnError) {
  json manifest = ManifestV2();
  manifest["photos"][1]["light"] = "L07";
  WriteManifest(manifest);
  const std::string message = testing::ErrorOf([&] { Session::Load(ManifestPath()); });
  EXPECT_NE(message.find(ManifestPath() + ": /photos/1/light"), std::string::npos) << message;
  EXPECT_NE(message.find("\"L07\""), std::string::npos) << message;
  EXPECT_NE(message.find("L01, L02, L03"), std::string::npos) << message;
}

// With several lights, a measurement photo must name its light; ids are unique and non-empty; a
// light's marker block names its light too; `light` and `lights` together are an error.
TEST_F(SessionV2Test, LightReferencesAreChecked) {
  json manifest = ManifestV2();
  manifest["photos"][1].erase("light");
  ExpectLoadError(manifest, "/photos/1/light");
  manifest = ManifestV2();
  manifest["lights"][2]["id"] = "L01";
  ExpectLoadError(manifest, "/lights/2/id");
  manifest = ManifestV2();
  manifest["lights"][1]["id"] = "";
  ExpectLoadError(manifest, "/lights/1/id");
  manifest = ManifestV2();
  manifest["lights"][0].erase("id");
  ExpectLoadError(manifest, "/lights/0/id");
  manifest = ManifestV2();
  manifest["light"] = manifest["lights"][0];
  ExpectLoadError(manifest, "/light");
  manifest = ManifestV2();
  manifest["calibration"]["white_reference"]["photos"][0]["light"] = "nope";
  ExpectLoadError(manifest, "/calibration/white_reference/photos/0/light");
  manifest = ManifestV2();
  manifest["targets"] = json::parse(R"({"dictionary": "DICT_4X4_50",
      "reference": [{"id": 0, "corners": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]}],
      "light": {"size": 0.06, "markers": [{"id": 20, "light_in_marker": [0, 0, 0]}]}})");
  ExpectLoadError(manifest, "/targets/light/light");
  manifest["targets"]["light"]["light"] = "L01";
  WriteManifest(manifest);
  EXPECT_EQ(Session::Load(ManifestPath()).targets->light->light, 0u);
}

// Bad input: a light without an intensity that no calibration measures is one clear error naming
// the light.
TEST_F(SessionV2Test, LightWithoutIntensityAndNoCalibrationIsAnError) {
  json manifest = ManifestV2();
  manifest.erase("calibration");
  WriteManifest(manifest);
  const std::string message = testing::ErrorOf([&] { Session::Load(ManifestPath()); });
  EXPECT_NE(message.find(ManifestPath() + ": /lights/2"), std::string::npos) << message;
  EXPECT_NE(message.find("light L03 has no intensity and no calibration measures it"), std::string::npos) << message;
  // A white reference under another light does not measure this one.
  manifest = ManifestV2();
  manifest["calibration"]["white_reference"]["photos"][0]["light"] = "L01";
  ExpectLoadError(manifest, "/lights/2");
  // The shorthand: the same rule.
  manifest = ValidManifest();
  manifest["version"] = 2;
  manifest["light"].erase("intensity");
  ExpectLoadError(manifest, "/light");
  // Version 1: the same rule (a white reference may measure the one light; without one it is an error).
  manifest["version"] = 1;
  ExpectLoadError(manifest, "/light");
}

// "position": "unknown" (session init's light on a marker card) needs the light's markers; without them
// it is an error naming the field.
TEST_F(SessionV2Test, UnknownLightPositionNeedsTheLightsMarkers) {
  json manifest = ValidManifest();
  manifest["light"]["position"] = "unknown";
  ExpectLoadError(manifest, "/light/position");
  WriteManifest(manifest);
  const std::string message = testing::ErrorOf([&] { Session::Load(ManifestPath()); });
  EXPECT_NE(message.find("no light markers"), std::string::npos) << message;
}

// Masks: missing files are errors at load; masks on white-reference and targets photos are refused.
TEST_F(SessionV2Test, MaskKeysAreChecked) {
  json manifest = ManifestV2();
  manifest["photos"][0]["mask"] = "masks/missing.png";
  ExpectLoadError(manifest, "/photos/0/mask");
  manifest = ManifestV2();
  manifest["mask"] = "masks/missing.png";
  ExpectLoadError(manifest, "/mask");
  manifest = ManifestV2();
  manifest["calibration"]["white_reference"]["photos"][0]["mask"] = "masks/all.png";
  ExpectLoadError(manifest, "/calibration/white_reference/photos/0/mask");
  manifest = ManifestV2();
  manifest["photos"][0]["role"] = "targets";
  ExpectLoadError(manifest, "/photos/0/mask");
}

// Bad input: a mask of the wrong size is one clear error naming both the mask and its photo.
TEST_F(SessionV2Test, MaskOfTheWrongSizeNamesBothFiles) {
  WriteImage(Path("masks/img0.png"), Image(kWidth + 1, kHeight, 1), PixelFormat::kUint8);
  WriteManifest(ManifestV2());
  const Session session = Session::Load(ManifestPath());
  const std::string message = testing::ErrorOf([&] { session.CheckPhotos(); });
  EXPECT_NE(message.find(Path("masks/img0.png")), std::string::npos) << message;
  EXPECT_NE(message.find(Path("photos/img0.png")), std::string::npos) << message;
  EXPECT_NE(message.find("9x6"), std::string::npos) << message;
}

}  // namespace
}  // namespace ibrdf
