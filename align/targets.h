// Print-ready targets: the sheets a lab prints to capture a session ibrdf can align,
// and the session's matching "targets" block. Three sheets, each as SVG (vector, exact printed sizes in
// millimetres) and PNG (at a stated DPI, with the DPI in the file):
//   - platform: a dark disc (the sphere's silhouette stays against black) with a ring of ArUco markers
//     of known layout on white cards, a cross where the sample rests, a scale bar and the sizes;
//   - light card: markers in a row with a cross where the light's emitter goes, for `ibrdf align` to
//     find the light (targets.light);
//   - white card: a white patch framed by markers, for `ibrdf align` to pose the white reference
//     (targets.white_reference);
//   - ChArUco board: the calibration board `ibrdf align --calibrate` reads (with its board.json).
// The world frame of a session aligned to the platform: origin at the platform's centre on the paper,
// x to the right of the print, y up the print, z out of the paper (up). The defaults are the layout of
// `ibrdf synth --targets`, so a synthetic capture and a printed one share one targets block.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "align/intrinsic_calibration.h"
#include "core/session.h"

namespace ibrdf {

struct TargetSheetsOptions {
  std::string dictionary = "DICT_4X4_50";  // ArUco dictionary of the platform and light markers
  // The platform: ring_count markers, ids 0 .., of printed side marker_size (border included), their
  // centres ring_radius from the centre at angles (k + 0.5) x 360 / ring_count degrees from +x, upright,
  // each on a white card of card_margin marker sides around it, on a black disc of platform_radius.
  int ring_count = 12;
  double marker_size = 0.028;      // metres
  double ring_radius = 0.1;        // metres
  double platform_radius = 0.135;  // metres
  double card_margin = 0.25;       // marker sides
  // The light card: light_marker_count markers of light_marker_size, ids from light_marker_first_id, in a
  // row (centres light_marker_size x (1 + 2 card_margin) apart), with the emitter's cross light_drop above
  // the row's centre; the emitter lies light_offset in front of the card (towards the sample). 0 markers:
  // no light card.
  int light_marker_count = 2;
  int light_marker_first_id = 20;
  double light_marker_size = 0.06;  // metres
  double light_drop = 0.08;         // metres, the row's centre line to the emitter, straight up the card
  double light_offset = 0.0;        // metres, in front of the card
  // The white reference's card: a white patch (Spectralon) of white_patch_size mounted
  // at the card's centre, framed by 4 markers of white_marker_size at the corners (ids from
  // white_marker_first_id: top-left, top-right, bottom-right, bottom-left), each card_margin marker sides
  // clear of the patch. white_patch_thickness: how far the patch's surface stands in front of the
  // printed card (a tile's thickness; the markers' corners then lie that far behind the patch's plane).
  bool white_card = true;
  int white_marker_first_id = 40;
  double white_marker_size = 0.02;     // metres
  double white_patch_size = 0.05;      // metres, the patch's side
  double white_patch_thickness = 0.0;  // metres
  bool charuco = true;              // the calibration board sheet
  CharucoBoardSpec board;           // its layout (align/intrinsic_calibration.h)
  double dpi = 600.0;               // the PNGs' resolution, dots per inch
  double scale_bar = 0.1;           // metres, the scale bar's printed length
  bool overwrite = false;           // replace an existing output folder
  bool Check(std::string* why) const;
};

// What was written; reads as not written until the folder was committed.
struct TargetSheetsResult {
  bool written = false;
  std::vector<std::string> files;        // relative to the output folder
  TargetsSpec targets;                   // the session's targets block (also OUT/targets.json)
  std::vector<std::string> sheet_sizes;  // "platform.svg: 290 x 330 mm (fits A3 portrait)"
  std::string BriefReport() const;
};

// The white reference's card markers: 4 markers of side `marker_size` (ids first_id ..) framing a square
// patch of side `patch_size` at the corners, `margin` marker sides clear of it, their corners in the
// card's frame (origin at the patch's centre on its surface, x right, y up the print, z out of the
// patch) at z = -patch_thickness. Shared by the printed card and `ibrdf synth`'s rendered one.
WhiteReferenceTargetsSpec WhiteCardLayout(int first_id, double marker_size, double patch_size, double margin,
                                          double patch_thickness);

// The targets block of the layout (reference ring, light markers, the white card's markers; no unknown
// layout, no sample markers).
TargetsSpec TargetLayout(const TargetSheetsOptions& options);

// The targets block as session.json holds it.
nlohmann::json TargetsToJson(const TargetsSpec& targets);

// Writes `out_dir`: platform.svg/.png, light-card.svg/.png (with light markers), white-card.svg/.png
// (with white_card), charuco.svg/.png and
// board.json (with charuco), targets.json ({"targets": ...}) and README.txt (how to print and check).
// The folder appears only when complete. Throws Error for bad options (marker ids beyond the dictionary,
// markers that overlap, a ring outside the platform).
TargetSheetsResult WriteTargetSheets(const TargetSheetsOptions& options, const std::string& out_dir);

}  // namespace ibrdf
