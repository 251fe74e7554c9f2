// ibrdf align: a session's geometry from its own photos (coded targets, silhouettes).
#include <filesystem>

#include <nlohmann/json.hpp>

#include "align/aligner.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/session.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

void AddAlignCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "align",
      "Find the session's geometry from its photos: camera poses from ArUco markers of known layout\n"
      "(PnP, then Ceres with a robust loss), the light from markers on it, and a sphere's centre and radius\n"
      "from its silhouettes. Photos with \"role\": \"targets\" are posed and kept but not used for the sample. Writes\n"
      "OUT/session.json (the aligned session; photos stay where they are) and OUT/alignment.json (residuals).");
  struct Args {
    std::string session, out;
    AlignOptions options;
    bool overwrite = false, no_sphere = false, no_light = false;
  };
  auto args = std::make_shared<Args>();
  command->add_option("session", args->session, "Session folder or session.json with a \"targets\" block")->required();
  command->add_option("--out", args->out, "Folder for the aligned session")->required();
  command->add_option("--min-markers", args->options.min_markers_per_image, "Reference markers a photo needs")->capture_default_str();
  command->add_option("--max-rms-px", args->options.max_image_rms_px, "Drop photos whose corner RMS exceeds this")->capture_default_str();
  command->add_flag("--no-sphere", args->no_sphere, "Keep the sphere as given instead of fitting its silhouettes");
  command->add_flag("--no-light", args->no_light, "Keep the light as given instead of finding it from its markers");
  command->add_flag("--overwrite", args->overwrite, "Replace an existing output folder");
  command->callback([args] {
    StageLog stage("align");
    const Session session = Session::Load(args->session);
    if (SameFile(args->out, session.directory)) ThrowError(args->out, "is the input session's folder; no stage overwrites its inputs");
    AlignOptions options = args->options;
    options.fit_sphere = !args->no_sphere;
    options.fit_light = !args->no_light;
    AtomicDirectory directory(args->out, args->overwrite);
    AlignResult result = AlignSession(session, options);
    for (const ImageAlignment& image : result.images) {
      if (!image.used) Log(1, "dropped photo " + session.photos[image.photo].file + ": " + image.dropped_reason);
    }
    // Photos stay in the input session; the aligned manifest points at them.
    const fs::path final_dir = fs::absolute(args->out).lexically_normal();
    for (PhotoSpec& photo : result.session.photos) {
      const fs::path absolute = fs::absolute(ResolvePath(session.directory, photo.file)).lexically_normal();
      photo.file = absolute.lexically_relative(final_dir).string();
    }
    result.session.name = session.name + "-aligned";
    result.session.Save((fs::path(directory.temporary_path()) / "session.json").string());
    WriteJsonFile((fs::path(directory.temporary_path()) / "alignment.json").string(), ToJson(result));
    directory.Commit();
    Log(1, result.BriefReport());
    Log(1, "aligned session written to " + args->out + "/session.json");
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(30, AddAlignCommand);

}  // namespace ibrdf
