// ibrdf library: finished runs collected into one material library folder (report/material_library.h):
// each material's MERL table, fits, renderer snippets and .bsdf under its name, lit spheres, index.json
// and an index.html gallery. Docs: docs/workflow.md, "The material library".
#include <filesystem>

#include "apps/commands.h"
#include "core/error.h"
#include "core/logging.h"
#include "report/material_library.h"
#include "workflow/batch_config.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

void AddLibraryCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "library",
      "Collect finished `ibrdf run` folders into a material library: DIR/materials/NAME/ (MERL table,\n"
      "fits, pbrt-v4/Mitsuba 3 snippets, .bsdf, lit sphere, report), DIR/index.json (each run's figures or\n"
      "its error) and DIR/index.html (a gallery and a comparison plot in the incidence plane). With\n"
      "--batch, the runs of an `ibrdf batch` config, into its OUT/library (docs/workflow.md).");
  struct Args {
    std::vector<std::string> runs;
    std::string batch;
    std::vector<std::string> compare;
    LibraryOptions options;
  };
  auto args = std::make_shared<Args>();
  command->add_option("runs", args->runs, "Run folders of `ibrdf run` (each material named after its folder)");
  command->add_option("--batch", args->batch, "An `ibrdf batch` config: its runs, logs and library folder")
      ->excludes(command->get_option("runs"));
  command->add_option("--out", args->options.out_dir, "The library folder (default with --batch: OUT/library)");
  command
      ->add_option("--compare", args->compare,
                   "Materials in the comparison plot (default: the batch config's, else the first 8)")
      ->delimiter(',');
  AddDeprecatedAlias(*command,
                     command->add_option("--sphere-size-px", args->options.sphere_size, "Lit sphere images, pixels")
                         ->capture_default_str(),
                     "--sphere-size", args->options.sphere_size);
  command->add_flag("--overwrite", args->options.overwrite, "Replace an existing folder that is not a library");
  command->callback([args] {
    std::vector<LibraryEntry> entries;
    LibraryOptions options = args->options;
    if (!args->batch.empty()) {
      const BatchConfig config = ReadBatchConfig(args->batch);
      for (const BatchEntry& entry : config.entries) {
        entries.push_back({entry.name, entry.run_dir, entry.input, entry.log_path});
      }
      // The batch's own library folder is rebuilt whole on every call.
      if (options.out_dir.empty()) {
        options.out_dir = config.LibraryDir();
        options.overwrite = true;
      }
      if (args->compare.empty()) options.compare = config.compare;
    } else {
      if (args->runs.empty()) ThrowError("ibrdf library", "give run folders, or --batch CONFIG");
      if (options.out_dir.empty()) ThrowError("ibrdf library", "--out is required with run folders");
      for (const std::string& run : args->runs) {
        if (!fs::is_directory(run)) ThrowError(run, "is not a folder (expected an `ibrdf run` folder)");
        const std::string name = fs::path(fs::absolute(run).lexically_normal()).filename().string();
        entries.push_back({name, run, "", ""});
      }
    }
    if (!args->compare.empty()) options.compare = args->compare;
    RequireValidOptions(options, "ibrdf library");
    const LibraryResult result = BuildLibrary(entries, options);
    Log(1, "library: " + result.BriefReport());
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(95, AddLibraryCommand);

}  // namespace ibrdf
