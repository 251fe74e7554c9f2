// ibrdf targets: print-ready marker sheets and the session's targets block (align/targets.h).
#include <iostream>

#include "align/targets.h"
#include "apps/commands.h"

namespace ibrdf {

IBRDF_COMMAND(5, Targets) {
  auto* c = app.add_subcommand(
      "targets",
      "Write print-ready sheets (SVG and PNG at --dpi, with a scale bar): the marker platform, the light's marker\n"
      "card, the white reference's card and a ChArUco board (with board.json), and targets.json, the session's\n"
      "\"targets\" block. Defaults: the layout of `ibrdf synth --targets`.");
  struct Args {
    TargetSheetsOptions o;
    std::string out;
  };
  auto args = std::make_shared<Args>();
  TargetSheetsOptions& o = args->o;
  AddOutputFlags(*c, args->out, o.overwrite, "Folder for the sheets and targets.json",
                 "Replace an existing output folder");
  AddOption(*c, "--dictionary", o.dictionary, "ArUco dictionary of the platform and light markers");
  AddOption(*c, "--ring-count", o.ring_count, "Markers on the platform's ring");
  AddMillimetres(*c, "--marker-mm", o.marker_size, "Printed side of a platform marker");
  AddMillimetres(*c, "--ring-radius-mm", o.ring_radius, "Platform centre to the markers' centres");
  AddMillimetres(*c, "--platform-radius-mm", o.platform_radius, "Radius of the black platform disc");
  AddOption(*c, "--light-markers", o.light_marker_count, "Markers on the light's card (0: no card)");
  AddMillimetres(*c, "--light-marker-mm", o.light_marker_size, "Printed side of a light marker");
  AddMillimetres(*c, "--light-drop-mm", o.light_drop, "The emitter's cross above the markers' centre line");
  AddMillimetres(*c, "--light-offset-mm", o.light_offset, "The emitter's distance in front of the card");
  AddClearingFlag(*c, "--no-white-card", o.white_card, "No white-reference card sheet");
  AddMillimetres(*c, "--white-marker-mm", o.white_marker_size, "Printed side of a white card's marker");
  AddOption(*c, "--white-marker-first-id", o.white_marker_first_id, "Id of the white card's first marker");
  AddMillimetres(*c, "--white-patch-mm", o.white_patch_size, "Side of the white patch the card frames");
  AddMillimetres(*c, "--white-patch-thickness-mm", o.white_patch_thickness,
                 "How far the patch's surface stands in front of the card (a tile's thickness)");
  AddClearingFlag(*c, "--no-charuco", o.charuco, "No calibration board sheet");
  AddOption(*c, "--board-squares-x", o.board.squares_x, "ChArUco squares across");
  AddOption(*c, "--board-squares-y", o.board.squares_y, "ChArUco squares down (odd)");
  AddMillimetres(*c, "--board-square-mm", o.board.square_size, "ChArUco square side");
  AddMillimetres(*c, "--board-marker-mm", o.board.marker_size, "ChArUco marker side");
  AddOption(*c, "--board-dictionary", o.board.dictionary, "ChArUco dictionary");
  AddOption(*c, "--dpi", o.dpi, "Resolution of the PNG sheets");
  c->callback([args] {
    RequireValidOptions(args->o, "ibrdf targets");
    const TargetSheetsResult result = WriteTargetSheets(args->o, args->out);
    Log(1, result.BriefReport());
    for (const std::string& file : result.files) std::cout << args->out << "/" << file << "\n";
    std::cout << "print at 100 % and measure the scale bars; targets block: " << args->out << "/targets.json\n";
  });
}

}  // namespace ibrdf
