// ibrdf library: finished runs collected into one material library folder (report/material_library.h):
// each material's MERL table, fits, renderer snippets and .bsdf under its name, lit spheres, index.json
// and an index.html gallery. Docs: docs/workflow.md, "The material library".
#include "apps/commands.h"
#include "core/error.h"
#include "report/material_library.h"
#include "workflow/batch_config.h"

namespace ibrdf {

IBRDF_COMMAND(95, Library) {
  auto* c = app.add_subcommand(
      "library",
      "Collect finished `ibrdf run` folders into a material library: DIR/materials/NAME/ (MERL table, fits,\n"
      "renderer snippets, .bsdf, lit sphere, report), DIR/index.json and DIR/index.html (a gallery, a comparison\n"
      "plot); with --batch, the runs of an `ibrdf batch` config into its OUT/library (docs/workflow.md).");
  struct Args {
    std::vector<std::string> runs;
    std::string batch;
    LibraryOptions o;
  };
  auto args = std::make_shared<Args>();
  LibraryOptions& o = args->o;
  c->add_option("runs", args->runs, "Run folders of `ibrdf run` (each material named after its folder)");
  c->add_option("--batch", args->batch, "An `ibrdf batch` config: its runs, logs and library folder")
      ->excludes(c->get_option("runs"));
  c->add_option("--out", o.out_dir, "The library folder (default with --batch: OUT/library)");
  c->add_option("--compare", o.compare, "Materials in the comparison plot (default: the batch's, else the first 8)")
      ->delimiter(',');
  AddRenamedOption(*c, "--sphere-size-px", "--sphere-size", o.sphere_size, "Lit sphere images, pixels");
  c->add_flag("--overwrite", o.overwrite, "Replace an existing folder that is not a library");
  c->callback([args] {
    LibraryOptions options = args->o;
    std::vector<LibraryEntry> entries;
    if (!args->batch.empty()) {
      const BatchConfig config = ReadBatchConfig(args->batch);
      for (const BatchEntry& e : config.entries) entries.push_back({e.name, e.run_dir, e.input, e.log_path});
      // The batch's own library folder is rebuilt whole on every call.
      if (options.out_dir.empty()) {
        options.out_dir = config.LibraryDir();
        options.overwrite = true;
      }
      if (options.compare.empty()) options.compare = config.compare;
    } else {
      if (args->runs.empty()) ThrowError("ibrdf library", "give run folders, or --batch CONFIG");
      if (options.out_dir.empty()) ThrowError("ibrdf library", "--out is required with run folders");
      entries = LibraryEntriesOfRuns(args->runs);
    }
    RequireValidOptions(options, "ibrdf library");
    Log(1, "library: " + BuildLibrary(entries, options).BriefReport());
  });
}

}  // namespace ibrdf
