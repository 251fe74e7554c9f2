// COLMAP into the metric target frame: a model written from a synthetic session's true poses after a
// known similarity is brought back within 1e-6 (relative), an outlier image does not pull it, the real
// test model is aligned to a transformed copy of itself, what cannot be aligned is a clear error, the
// merge of COLMAP's and the targets' poses photo by photo, and the align stage with a COLMAP model.
#include "align/colmap_alignment.h"

#include <cmath>
#include <filesystem>
#include <functional>
#include <random>

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "align/align_stage.h"
#include "core/error.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "tests/error_of.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::MakeSession;
using testing::MaterialPath;
using testing::ScratchDir;

const std::string kModel = std::string(IBRDF_SHARED_DATA_DIR) + "/colmap-test-model/sparse/0";

using testing::ErrorOf;

Similarity3d RandomSimilarity(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Similarity3d s;
  s.scale = 0.37;
  s.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
  s.translation = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  return s;
}

// camera_from_colmap of a camera whose metric pose is camera_from_world, with world = S * colmap.
Rigid3d ColmapPose(const Rigid3d& camera_from_world, const Similarity3d& world_from_colmap) {
  const Eigen::Quaterniond rotation = camera_from_world.rotation * world_from_colmap.rotation;
  return Rigid3d(rotation,
                 (camera_from_world.rotation * world_from_colmap.translation + camera_from_world.translation) /
                     world_from_colmap.scale);
}

// A COLMAP model of the session's photos (named by file name only, as COLMAP names them when its
// image path is the photos folder), in the frame that `world_from_colmap` takes to the session's.
ColmapModel ModelOf(const Session& session, const Similarity3d& world_from_colmap) {
  ColmapModel model;
  model.cameras[1] = session.camera;
  for (size_t i = 0; i < session.photos.size(); ++i) {
    ColmapImage image;
    image.id = static_cast<uint32_t>(10 + i);
    image.camera_id = 1;
    image.name = fs::path(session.photos[i].file).filename().string();
    image.camera_from_world = ColmapPose(*session.photos[i].camera_from_world, world_from_colmap);
    image.points2d = {Eigen::Vector2d(10.5, 20.25)};
    image.point3d_ids = {7};
    model.images[image.id] = image;
  }
  ColmapPoint3D point;
  point.id = 7;
  point.xyz = Eigen::Vector3d(0.1, 0.2, 0.3);
  point.track = {{10, 0}};
  model.points[7] = point;
  return model;
}

void ExpectSimilarityNear(const Similarity3d& estimated, const Similarity3d& truth, double relative) {
  EXPECT_NEAR(estimated.scale / truth.scale, 1.0, relative);
  EXPECT_LT(estimated.rotation.angularDistance(truth.rotation), relative);
  EXPECT_LT((estimated.translation - truth.translation).norm(), relative * std::max(1.0, truth.translation.norm()));
}

TEST(Similarity3d, EstimateAndTransformPose) {
  const Similarity3d truth = RandomSimilarity(3);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::Matrix3Xd source(3, 6), target(3, 6);
  for (int k = 0; k < 6; ++k) {
    source.col(k) = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    target.col(k) = truth * source.col(k);
  }
  ExpectSimilarityNear(Similarity3d::Estimate(source, target, "test"), truth, 1e-12);
  // A point seen by a camera: the same pixel ray in both frames, the depth scaled.
  const Rigid3d camera_from_source(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized(),
                                   Eigen::Vector3d(0.3, -0.2, 2.0));
  const Rigid3d camera_from_target = truth.TransformPose(camera_from_source);
  const Eigen::Vector3d p_source(0.2, 0.1, 0.4);
  EXPECT_LT((camera_from_target * (truth * p_source) - truth.scale * (camera_from_source * p_source)).norm(), 1e-12);
  const Eigen::Vector3d back = truth.Inverse() * (truth * p_source);
  EXPECT_LT((back - p_source).norm(), 1e-12);
  // Collinear points cannot fix a rotation about their line.
  Eigen::Matrix3Xd line(3, 4);
  for (int k = 0; k < 4; ++k) line.col(k) = Eigen::Vector3d(k, 2.0 * k, 0.0);
  EXPECT_NE(ErrorOf([&] { Similarity3d::Estimate(line, line, "centres"); }).find("collinear"), std::string::npos);
}

TEST(ColmapAlignment, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(ColmapAlignmentOptions().Check(&why)) << why;
}

// The alignment's test: a COLMAP model written from the true poses after a random similarity, through the
// binary and the text writers and readers, recovered within 1e-6 relative; one image moved 5 cm is an
// outlier and keeps no say in the similarity.
TEST(ColmapAlignment, RecoversTheSimilarityOfASyntheticSession) {
  ScratchDir dir;
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 8;
  options.rig.camera_elevation_deg = 20.0;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  const Similarity3d truth = RandomSimilarity(11);
  ColmapModel written = ModelOf(session, truth);
  // Photo 5's COLMAP pose is misregistered by 5 cm.
  ColmapImage& outlier = written.images.at(15);
  outlier.camera_from_world.translation += Eigen::Vector3d(0.05, 0.0, 0.0) / truth.scale;
  for (const std::string format : {"bin", "txt"}) {
    const std::string model_dir = dir / ("model-" + format);
    fs::create_directories(model_dir);
    if (format == "bin") {
      written.WriteBinary(model_dir);
    } else {
      written.WriteText(model_dir);
    }
    const ColmapModel model = ColmapModel::Read(model_dir);
    ASSERT_EQ(model.images.size(), session.photos.size());
    std::vector<std::string> files;
    std::vector<std::optional<Rigid3d>> poses;
    for (const PhotoSpec& photo : session.photos) {
      files.push_back(photo.file);
      poses.push_back(photo.camera_from_world);
    }
    const ColmapAlignment alignment = AlignColmapModel(model, files, poses, ColmapAlignmentOptions(), model_dir);
    ASSERT_TRUE(alignment.success);
    EXPECT_EQ(alignment.matched, 8);
    EXPECT_EQ(alignment.both, 8);
    EXPECT_EQ(alignment.inliers, 7) << alignment.BriefReport();
    EXPECT_FALSE(alignment.photos[5].inlier);
    EXPECT_NEAR(alignment.photos[5].center_error_m, 0.05, 1e-6);
    ExpectSimilarityNear(alignment.world_from_colmap, truth, 1e-6);
    EXPECT_LT(alignment.rms_center_error_m, 1e-7);
    for (size_t i = 0; i < session.photos.size(); ++i) {
      if (i == 5) continue;
      ASSERT_TRUE(alignment.photos[i].metric_pose);
      const Rigid3d& expected = *session.photos[i].camera_from_world;
      EXPECT_LT((alignment.photos[i].metric_pose->translation - expected.translation).norm(), 1e-6) << "photo " << i;
      EXPECT_LT(alignment.photos[i].metric_pose->rotation.angularDistance(expected.rotation), 1e-6) << "photo " << i;
    }
    ASSERT_NE(SharedColmapCamera(model, alignment), nullptr);
    EXPECT_EQ(SharedColmapCamera(model, alignment)->params, session.camera.params);
    const nlohmann::json json = ToJson(alignment);
    EXPECT_EQ(json["inliers"], 7);
    EXPECT_EQ(json["photos"][5]["inlier"], false);
  }
}

// The real model (23 images, one camera each): the similarity to a transformed copy of its own poses.
TEST(ColmapAlignment, RealModelToATransformedCopyOfItself) {
  if (!fs::exists(kModel + "/cameras.bin"))
    GTEST_SKIP() << "../shared/data/colmap-test-model is absent: real-data test skipped";
  const ColmapModel model = ColmapModel::Read(kModel);
  ASSERT_EQ(model.images.size(), 23u);
  const Similarity3d truth = RandomSimilarity(5);
  std::vector<std::string> files;
  std::vector<std::optional<Rigid3d>> poses;
  for (const auto& [id, image] : model.images) {
    files.push_back("photos/" + image.name);
    poses.push_back(truth.TransformPose(image.camera_from_world));
  }
  const ColmapAlignment alignment = AlignColmapModel(model, files, poses, ColmapAlignmentOptions(), kModel);
  EXPECT_EQ(alignment.matched, 23);
  EXPECT_EQ(alignment.inliers, 23);
  ExpectSimilarityNear(alignment.world_from_colmap, truth, 1e-9);
  EXPECT_EQ(SharedColmapCamera(model, alignment), nullptr);  // one camera per image
  // Written and read back, binary and text agree with the original to the last bit the text keeps.
  ScratchDir dir;
  model.WriteBinary(dir.str());
  const ColmapModel binary = ColmapModel::Read(dir.str());
  EXPECT_EQ(binary.points.size(), model.points.size());
  for (const auto& [id, image] : model.images) {
    EXPECT_EQ(binary.images.at(id).camera_from_world.translation, image.camera_from_world.translation);
    EXPECT_EQ(binary.images.at(id).points2d, image.points2d);
    EXPECT_EQ(binary.images.at(id).point3d_ids, image.point3d_ids);
  }
  EXPECT_EQ(fs::file_size(dir / "points3D.bin"), fs::file_size(kModel + "/points3D.bin"));
  EXPECT_EQ(fs::file_size(dir / "images.bin"), fs::file_size(kModel + "/images.bin"));
}

TEST(ColmapAlignment, TooFewPhotosPosedBothWaysIsAnError) {
  ColmapModel model;
  model.cameras[1] = Camera::Create(CameraModelId::kPinhole, 100, 100, {100, 100, 50, 50});
  for (uint32_t id = 1; id <= 4; ++id) {
    ColmapImage image;
    image.id = id;
    image.camera_id = 1;
    image.name = "img" + std::to_string(id) + ".png";
    image.camera_from_world.translation = Eigen::Vector3d(id, id * id, 1.0);
    model.images[id] = image;
  }
  std::vector<std::string> files = {"photos/img1.png", "photos/img2.png", "photos/other.png"};
  std::vector<std::optional<Rigid3d>> poses(3, Rigid3d());
  std::string message = ErrorOf([&] { AlignColmapModel(model, files, poses, ColmapAlignmentOptions(), "m"); });
  EXPECT_NE(message.find("m: 2 of the session's 3 photos are in the COLMAP model"), std::string::npos) << message;
  // Photos the targets could not pose do not count.
  files = {"img1.png", "img2.png", "img3.png"};
  poses = {Rigid3d(), std::nullopt, Rigid3d()};
  message = ErrorOf([&] { AlignColmapModel(model, files, poses, ColmapAlignmentOptions(), "m"); });
  EXPECT_NE(
      message.find("3 of the session's 3 photos are in the COLMAP model (matched by file name) and 2 of those were "
                   "posed by the targets; the similarity needs 3"),
      std::string::npos)
      << message;
  // Poses that no similarity reconciles (every target-based centre the same): refused, not a wrong answer.
  files = {"img1.png", "img2.png", "img3.png", "img4.png"};
  message = ErrorOf([&] {
    AlignColmapModel(model, files, std::vector<std::optional<Rigid3d>>(4, Rigid3d()), ColmapAlignmentOptions(), "m");
  });
  EXPECT_NE(message.find("m: no similarity brings 3 of the 4 photos"), std::string::npos) << message;
}

// Photo by photo: an inlier takes COLMAP's pose, an outlier keeps the targets', a photo only COLMAP
// registered takes COLMAP's, one only the targets posed keeps theirs, one neither posed is left out; the
// camera becomes COLMAP's shared camera of the session's size unless the camera is kept.
TEST(ColmapAlignment, MergeColmapPosesPhotoByPhoto) {
  Session input;
  input.camera = Camera::Create(CameraModelId::kPinhole, 100, 80, {100, 100, 50, 40});
  for (int i = 0; i < 5; ++i) {
    PhotoSpec photo;
    photo.file = "photos/" + std::to_string(i) + ".png";
    input.photos.push_back(photo);
  }
  Session aligned = input;
  aligned.name = "aligned";
  const auto pose = [](double x) { return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0, 0)); };
  ColmapAlignment colmap;
  colmap.photos.resize(5);
  colmap.photos[0].metric_pose = pose(1.0);  // inlier
  colmap.photos[0].target_pose = pose(1.1);
  colmap.photos[0].inlier = true;
  colmap.photos[1].metric_pose = pose(2.0);  // outlier
  colmap.photos[1].target_pose = pose(2.1);
  colmap.photos[2].metric_pose = pose(3.0);  // COLMAP only
  colmap.photos[3].target_pose = pose(4.1);  // targets only
  ColmapModel model;
  model.cameras[1] = Camera::Create(CameraModelId::kPinhole, 100, 80, {101, 101, 50, 40});
  for (uint32_t id : {1u, 2u, 3u}) {
    ColmapImage image;
    image.id = id;
    image.camera_id = 1;
    model.images[id] = image;
    colmap.photos[id - 1].image_id = id;
  }
  const Session merged = MergeColmapPoses(input, aligned, model, colmap, /*keep_camera=*/false);
  EXPECT_EQ(merged.name, "aligned");
  ASSERT_EQ(merged.photos.size(), 4u);
  const double expected[] = {1.0, 2.1, 3.0, 4.1};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(merged.photos[i].file, input.photos[i].file);
    EXPECT_EQ(merged.photos[i].camera_from_world->translation.x(), expected[i]) << "photo " << i;
  }
  EXPECT_EQ(merged.camera.params, model.cameras[1].params);
  EXPECT_EQ(MergeColmapPoses(input, aligned, model, colmap, /*keep_camera=*/true).camera.params, input.camera.params);
  model.cameras[1].width = 200;  // not the session's size: the session's camera stays
  EXPECT_EQ(MergeColmapPoses(input, aligned, model, colmap, false).camera.params, input.camera.params);
}

// End to end through the align stage with a COLMAP model: a target session with a model written from
// the true poses after a similarity: the aligned session holds the true poses (within the target-based
// similarity's error) and COLMAP's camera; alignment.json reports the similarity.
TEST(ColmapAlignment, AlignStageWithAColmapModel) {
  ScratchDir dir;
  SynthOptions options;
  options.targets.enabled = true;
  options.rig.camera_elevation_deg = 45.0;
  options.rig.num_photos = 6;
  const auto material = LoadMaterial(MaterialPath("bluepaint"));
  const Session session = Session::Load(MakeSession(dir / "s", options, *material));
  const Similarity3d truth = RandomSimilarity(21);
  ColmapModel model = ModelOf(session, truth);
  model.cameras[1].params[0] *= 1.001;  // COLMAP's own estimate of the focal length
  fs::create_directories(dir / "model");
  model.WriteBinary(dir / "model");
  AlignStageOptions stage;
  stage.colmap_model = dir / "model";
  SetVerbosity(1);
  ::testing::internal::CaptureStderr();
  const AlignStageResult result = AlignSessionToFolder(Session::Load(dir / "s"), stage, dir / "aligned");
  const std::string log = ::testing::internal::GetCapturedStderr();
  SetVerbosity(0);
  ASSERT_TRUE(result.success);
  ASSERT_TRUE(result.colmap);
  EXPECT_NE(log.find("colmap: 6 photos registered"), std::string::npos) << log;
  const Session aligned = Session::Load(dir / "aligned");
  ASSERT_EQ(aligned.photos.size(), session.photos.size());
  EXPECT_EQ(aligned.camera.params, model.cameras[1].params);
  for (size_t i = 0; i < session.photos.size(); ++i) {
    const Rigid3d& expected = *session.photos[i].camera_from_world;
    const Rigid3d& estimated = *aligned.photos[i].camera_from_world;
    EXPECT_LT((estimated.Inverse().translation - expected.Inverse().translation).norm(), 0.5e-3) << "photo " << i;
    EXPECT_LT(estimated.rotation.angularDistance(expected.rotation) * 180.0 / M_PI, 0.05) << "photo " << i;
  }
  const nlohmann::json report = ReadJsonFile(dir / "aligned/alignment.json");
  EXPECT_EQ(report["colmap"]["inliers"], 6);
  EXPECT_NEAR(report["colmap"]["world_from_colmap"]["scale"].get<double>(), truth.scale, 1e-3 * truth.scale);
  // A model of other photos: a clear error, no output.
  for (auto& [id, image] : model.images) image.name = "other-" + image.name;
  model.WriteText(dir / "model");
  fs::remove(dir / "model/cameras.bin");
  const std::string message = ErrorOf([&] { AlignSessionToFolder(Session::Load(dir / "s"), stage, dir / "bad"); });
  EXPECT_NE(message.find("0 of the session's"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

}  // namespace
}  // namespace ibrdf
