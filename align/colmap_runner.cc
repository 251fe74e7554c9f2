#include "align/colmap_runner.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "align/colmap_model.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/logging.h"
#include "core/radiometry.h"
#include "core/statistics.h"
#include "core/subprocess.h"
#include "radiometry/linear_image.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// The last `count` lines of a text file, for error messages.
std::string Tail(const std::string& path, size_t count) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    lines.push_back(line);
    if (lines.size() > count) lines.erase(lines.begin());
  }
  std::string tail;
  for (const std::string& l : lines) tail += "\n  | " + l;
  return tail;
}

// Runs `executable arguments...` with stdout and stderr into `log_path`, headless (Qt offscreen).
int RunLogged(const std::string& executable, const std::vector<std::string>& arguments, const std::string& log_path) {
  std::vector<std::string> argv = {executable};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  SubprocessOptions options;
  options.log_path = log_path;
  options.environment = {{"QT_QPA_PLATFORM", "offscreen"}};
  return RunSubprocess(argv, options);
}

// An 8-bit, sRGB-encoded copy of a photo for SIFT: linearized, scaled so its 99.9th percentile is white.
void WriteColmapImage(const Session& session, size_t photo, const std::string& path) {
  Image image = ReadImage(session.PhotoPath(photo));
  LinearizeImage(session, photo, &image);
  std::vector<float> values;
  for (size_t i = 0; i < image.pixels.size(); i += 7) values.push_back(image.pixels[i]);
  float white = 1.0f;
  if (!values.empty()) {
    const float level = PercentileInPlace(&values, 0.999);
    if (level > 0.0f) white = level;
  }
  for (float& v : image.pixels) v = static_cast<float>(LinearToSrgb(std::min(1.0, double(v) / white)));
  fs::create_directories(fs::path(path).parent_path());
  WriteImage(path, image, PixelFormat::kUint8);
}

std::string ParamsList(const std::vector<double>& params) {
  std::ostringstream out;
  out.precision(17);
  for (size_t i = 0; i < params.size(); ++i) out << (i ? "," : "") << params[i];
  return out.str();
}

// COLMAP writes PNG copies as .png; other formats are re-encoded as PNG under the same stem plus
// ".png" so that FreeImage reads them (EXR, 16-bit TIFF, RAW).
std::string ColmapImageName(const std::string& photo_file) {
  const std::string name = fs::path(photo_file).lexically_normal().generic_string();
  std::string extension = fs::path(name).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return extension == ".png" ? name : name + ".png";
}

}  // namespace

bool ColmapRunnerOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION(!binary.empty());
  IBRDF_CHECK_OPTION_GE(num_threads, -1);
  IBRDF_CHECK_OPTION(num_threads != 0);  // -1: all cores
  IBRDF_CHECK_OPTION_GE(max_image_size, 100);
  return true;
}

std::string FindExecutable(const std::string& binary) {
  auto executable = [](const fs::path& p) { return fs::is_regular_file(p) && ::access(p.c_str(), X_OK) == 0; };
  if (binary.find('/') != std::string::npos) return executable(binary) ? binary : "";
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / binary;
    if (executable(candidate)) return candidate.string();
  }
  return "";
}

std::vector<ColmapCommand> ColmapCommands(const Session& session, const std::string& work_dir,
                                          const ColmapRunnerOptions& options) {
  const std::string database = (fs::path(work_dir) / "database.db").string();
  const std::string images = (fs::path(work_dir) / "images").string();
  const std::string list = (fs::path(work_dir) / "image-list.txt").string();
  const std::string threads = std::to_string(options.num_threads);
  ColmapCommand extract{
      "feature_extractor",
      {"--database_path", database, "--image_path", images, "--image_list_path", list, "--ImageReader.single_camera",
       options.single_camera ? "1" : "0", "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", threads,
       "--SiftExtraction.max_image_size", std::to_string(options.max_image_size)}};
  if (options.use_session_intrinsics) {
    extract.arguments.insert(extract.arguments.end(),
                             {"--ImageReader.camera_model", CameraModelName(session.camera.model),
                              "--ImageReader.camera_params", ParamsList(session.camera.params)});
  } else {
    extract.arguments.insert(extract.arguments.end(), {"--ImageReader.camera_model", "OPENCV"});
  }
  ColmapCommand match{
      "exhaustive_matcher",
      {"--database_path", database, "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads", threads}};
  ColmapCommand map{"mapper",
                    {"--database_path", database, "--image_path", images, "--image_list_path", list, "--output_path",
                     (fs::path(work_dir) / "sparse").string(), "--Mapper.num_threads", threads}};
  if (options.fix_intrinsics) {
    map.arguments.insert(map.arguments.end(),
                         {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
                          "--Mapper.ba_refine_extra_params", "0"});
  }
  return {extract, match, map};
}

ColmapRunResult RunColmap(const Session& session, const std::string& work_dir, const ColmapRunnerOptions& options,
                          bool overwrite) {
  Timer timer;
  std::string why;
  if (!options.Check(&why)) ThrowError("COLMAP options", why);
  const std::string executable = FindExecutable(options.binary);
  if (executable.empty()) {
    ThrowError(
        options.binary,
        "the COLMAP executable was not found (install it: apt-get install colmap; or name it with --colmap-binary)");
  }
  session.CheckPhotos();
  ColmapRunResult result;
  AtomicDirectory directory(work_dir, overwrite);
  const fs::path work = directory.temporary_path();
  fs::create_directories(work / "images");
  fs::create_directories(work / "sparse");
  fs::create_directories(work / "logs");
  {
    std::ofstream list(work / "image-list.txt");
    ProgressBar progress("colmap images", session.photos.size());
    for (size_t i = 0; i < session.photos.size(); ++i) {
      const std::string name = ColmapImageName(session.photos[i].file);
      if (name.rfind("..", 0) == 0 || fs::path(name).is_absolute()) {
        ThrowError(session.manifest_path + ": /photos/" + std::to_string(i) + "/file",
                   "COLMAP needs photos inside the session folder (got " + session.photos[i].file + ")");
      }
      WriteColmapImage(session, i, (work / "images" / name).string());
      list << name << "\n";
      progress.Add(1);
    }
    progress.Finish();
  }
  result.photos = static_cast<int>(session.photos.size());
  for (const ColmapCommand& command : ColmapCommands(session, work.string(), options)) {
    Timer step_timer;
    const std::string log = (work / "logs" / (command.step + ".log")).string();
    Log(1, "colmap " + command.step + " ...");
    std::vector<std::string> arguments = {command.step};
    arguments.insert(arguments.end(), command.arguments.begin(), command.arguments.end());
    const int code = RunLogged(executable, arguments, log);
    if (code != 0) {
      ThrowError(executable + " " + command.step,
                 "failed with exit code " + std::to_string(code) + "; the end of its log:" + Tail(log, 12));
    }
    result.steps.push_back({command.step, step_timer.ElapsedSeconds()});
    char line[120];
    std::snprintf(line, sizeof(line), "colmap %s: %.1f s", command.step.c_str(), result.steps.back().seconds);
    Log(1, line);
  }
  // The largest model.
  std::string best;
  for (const auto& entry : fs::directory_iterator(work / "sparse")) {
    if (!entry.is_directory() || !fs::exists(entry.path() / "images.bin")) continue;
    ++result.models;
    const ColmapModel model = ColmapModel::Read(entry.path().string());
    if (static_cast<int>(model.images.size()) > result.registered_images) {
      result.registered_images = static_cast<int>(model.images.size());
      best = entry.path().filename().string();
    }
  }
  if (best.empty()) {
    ThrowError(executable + " mapper",
               "found no model in " + std::to_string(result.photos) +
                   " photos (too little texture for SIFT, or too little overlap); the end of its log:" +
                   Tail((work / "logs" / "mapper.log").string(), 8));
  }
  std::ofstream(work / "model.txt") << "sparse/" << best << "\n";
  directory.Commit();
  result.work_dir = work_dir;
  result.model_dir = (fs::path(work_dir) / "sparse" / best).string();
  result.total_s = timer.ElapsedSeconds();
  return result;
}

std::string ColmapRunResult::BriefReport() const {
  std::string report = "colmap run: " + std::to_string(registered_images) + " of " + std::to_string(photos) +
                       " photos registered in the largest of " + std::to_string(models) + " models (";
  for (size_t i = 0; i < steps.size(); ++i) {
    char buffer[80];
    std::snprintf(buffer, sizeof(buffer), "%s%s %.1f s", i ? ", " : "", steps[i].step.c_str(), steps[i].seconds);
    report += buffer;
  }
  char buffer[60];
  std::snprintf(buffer, sizeof(buffer), "; %.1f s in all)", total_s);
  return report + buffer;
}

}  // namespace ibrdf
