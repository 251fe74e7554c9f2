// ibrdf targets: print-ready marker sheets and the session's targets block (align/targets.h).
#include <iostream>
#include <memory>

#include "align/targets.h"
#include "apps/commands.h"
#include "core/logging.h"

namespace ibrdf {
namespace {

void AddTargetsCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "targets",
      "Write print-ready sheets (SVG and PNG at --dpi, with a scale bar and the printed sizes): the marker\n"
      "platform, the light's marker card, the white reference's card and a ChArUco calibration board (with\n"
      "board.json), plus\n"
      "targets.json, the session's matching \"targets\" block. Defaults: the layout of `ibrdf synth --targets`.");
  struct Args {
    TargetSheetsOptions o;
    std::string out;
    double marker_mm = 0, ring_mm = 0, platform_mm = 0, light_marker_mm = 0, light_drop_mm = 0, light_offset_mm = 0,
           square_mm = 0, board_marker_mm = 0, white_marker_mm = 0, white_patch_mm = 0, white_thickness_mm = 0;
    bool no_charuco = false, no_white_card = false;
  };
  auto args = std::make_shared<Args>();
  TargetSheetsOptions& o = args->o;
  args->marker_mm = 1e3 * o.marker_size;
  args->ring_mm = 1e3 * o.ring_radius;
  args->platform_mm = 1e3 * o.platform_radius;
  args->light_marker_mm = 1e3 * o.light_marker_size;
  args->light_drop_mm = 1e3 * o.light_drop;
  args->light_offset_mm = 1e3 * o.light_offset;
  args->square_mm = 1e3 * o.board.square_size;
  args->board_marker_mm = 1e3 * o.board.marker_size;
  args->white_marker_mm = 1e3 * o.white_marker_size;
  args->white_patch_mm = 1e3 * o.white_patch_size;
  args->white_thickness_mm = 1e3 * o.white_patch_thickness;
  command->add_option("--out", args->out, "Folder for the sheets and targets.json")->required();
  command->add_option("--dictionary", o.dictionary, "ArUco dictionary of the platform and light markers")
      ->capture_default_str();
  command->add_option("--ring-count", o.ring_count, "Markers on the platform's ring")->capture_default_str();
  command->add_option("--marker-mm", args->marker_mm, "Printed side of a platform marker")->capture_default_str();
  command->add_option("--ring-radius-mm", args->ring_mm, "Platform centre to the markers' centres")
      ->capture_default_str();
  command->add_option("--platform-radius-mm", args->platform_mm, "Radius of the black platform disc")
      ->capture_default_str();
  command->add_option("--light-markers", o.light_marker_count, "Markers on the light's card (0: no card)")
      ->capture_default_str();
  command->add_option("--light-marker-mm", args->light_marker_mm, "Printed side of a light marker")
      ->capture_default_str();
  command->add_option("--light-drop-mm", args->light_drop_mm, "The emitter's cross above the markers' centre line")
      ->capture_default_str();
  command->add_option("--light-offset-mm", args->light_offset_mm, "The emitter's distance in front of the card")
      ->capture_default_str();
  command->add_flag("--no-white-card", args->no_white_card, "No white-reference card sheet");
  command->add_option("--white-marker-mm", args->white_marker_mm, "Printed side of a white card's marker")
      ->capture_default_str();
  command->add_option("--white-marker-first-id", o.white_marker_first_id, "Id of the white card's first marker")
      ->capture_default_str();
  command->add_option("--white-patch-mm", args->white_patch_mm, "Side of the white patch the card frames")
      ->capture_default_str();
  command
      ->add_option("--white-patch-thickness-mm", args->white_thickness_mm,
                   "How far the patch's surface stands in front of the card (a tile's thickness)")
      ->capture_default_str();
  command->add_flag("--no-charuco", args->no_charuco, "No calibration board sheet");
  command->add_option("--board-squares-x", o.board.squares_x, "ChArUco squares across")->capture_default_str();
  command->add_option("--board-squares-y", o.board.squares_y, "ChArUco squares down (odd)")->capture_default_str();
  command->add_option("--board-square-mm", args->square_mm, "ChArUco square side")->capture_default_str();
  command->add_option("--board-marker-mm", args->board_marker_mm, "ChArUco marker side")->capture_default_str();
  command->add_option("--board-dictionary", o.board.dictionary, "ChArUco dictionary")->capture_default_str();
  command->add_option("--dpi", o.dpi, "Resolution of the PNG sheets")->capture_default_str();
  command->add_flag("--overwrite", o.overwrite, "Replace an existing output folder");
  command->callback([args] {
    TargetSheetsOptions& options = args->o;
    options.marker_size = 1e-3 * args->marker_mm;
    options.ring_radius = 1e-3 * args->ring_mm;
    options.platform_radius = 1e-3 * args->platform_mm;
    options.light_marker_size = 1e-3 * args->light_marker_mm;
    options.light_drop = 1e-3 * args->light_drop_mm;
    options.light_offset = 1e-3 * args->light_offset_mm;
    options.board.square_size = 1e-3 * args->square_mm;
    options.board.marker_size = 1e-3 * args->board_marker_mm;
    options.charuco = !args->no_charuco;
    options.white_card = !args->no_white_card;
    options.white_marker_size = 1e-3 * args->white_marker_mm;
    options.white_patch_size = 1e-3 * args->white_patch_mm;
    options.white_patch_thickness = 1e-3 * args->white_thickness_mm;
    RequireValidOptions(options, "ibrdf targets");
    const TargetSheetsResult result = WriteTargetSheets(options, args->out);
    Log(1, result.BriefReport());
    for (const std::string& file : result.files) std::cout << args->out << "/" << file << "\n";
    std::cout << "print at 100 % and measure the scale bars; targets block: " << args->out << "/targets.json\n";
  });
}

}  // namespace

IBRDF_REGISTER_COMMAND(5, AddTargetsCommand);

}  // namespace ibrdf
