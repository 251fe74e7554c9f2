#include "align/targets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "align/markers.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"

namespace fs = std::filesystem;

namespace ibrdf {
namespace {

// A sheet: shapes in millimetres, sheet coordinates (x right, y down from the top-left corner).
struct Shape {
  enum class Kind { kRect, kDisc, kText } kind = Kind::kRect;
  double x = 0, y = 0, w = 0,
         h = 0;  // rect: corner and size; disc: centre and radius (w); text: baseline start, height (h)
  bool black = true;
  std::string text;
};

struct Sheet {
  std::string name;
  double width_mm = 0, height_mm = 0;
  std::vector<Shape> shapes;
  void Rect(double x, double y, double w, double h, bool black) {
    shapes.push_back({Shape::Kind::kRect, x, y, w, h, black, ""});
  }
  void Disc(double x, double y, double r, bool black) { shapes.push_back({Shape::Kind::kDisc, x, y, r, 0, black, ""}); }
  void Text(double x, double y, double height, const std::string& text, bool black = true) {
    shapes.push_back({Shape::Kind::kText, x, y, 0, height, black, text});
  }
  // A cross of arm `arm` and line width `line`.
  void Cross(double x, double y, double arm, double line, bool black) {
    Rect(x - arm, y - 0.5 * line, 2 * arm, line, black);
    Rect(x - 0.5 * line, y - arm, line, 2 * arm, black);
  }
};

std::string Mm(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f mm", value);
  return buffer;
}

// An upright marker of side `side_mm` centred at (cx, cy) on the sheet, on a white card of `margin`
// sides around it.
void DrawMarker(const MarkerDictionary& dictionary, int id, double cx, double cy, double side_mm, double margin,
                Sheet* sheet) {
  const double card = side_mm * (1.0 + 2.0 * margin);
  sheet->Rect(cx - 0.5 * card, cy - 0.5 * card, card, card, false);
  const int n = dictionary.modules();
  const std::vector<bool> modules = dictionary.Modules(id);
  const double cell = side_mm / n;
  const double x0 = cx - 0.5 * side_mm, y0 = cy - 0.5 * side_mm;
  for (int row = 0; row < n; ++row) {
    // Runs of black cells in the row, one rectangle each.
    for (int col = 0; col < n;) {
      if (modules[row * n + col]) {
        ++col;
        continue;
      }
      int end = col;
      while (end < n && !modules[row * n + end]) ++end;
      sheet->Rect(x0 + col * cell, y0 + row * cell, (end - col) * cell, cell, true);
      col = end;
    }
  }
  // The id in the card's bottom margin (black on white, whatever the card lies on).
  const double margin_mm = 0.5 * (card - side_mm);
  if (margin_mm >= 2.0) {
    sheet->Text(cx - 0.5 * side_mm, cy + 0.5 * side_mm + 0.8 * margin_mm, std::min(3.0, 0.6 * margin_mm),
                "id " + std::to_string(id));
  }
}

// A scale bar of `length_mm` with 10 mm ticks, its left end at (x, y), labelled.
void DrawScaleBar(double x, double y, double length_mm, Sheet* sheet) {
  sheet->Rect(x, y, length_mm, 1.0, true);
  for (int k = 0; k * 10.0 <= length_mm + 1e-9; ++k) sheet->Rect(x + k * 10.0 - 0.25, y - 3.0, 0.5, 4.0, true);
  sheet->Rect(x + length_mm - 0.25, y - 3.0, 0.5, 4.0, true);
  sheet->Text(x, y + 6.0, 3.5, "scale bar: " + Mm(length_mm) + " end to end (ticks every 10 mm); measure it");
}

std::string Svg(const Sheet& sheet) {
  std::ostringstream out;
  out.precision(6);
  out << std::fixed;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << sheet.width_mm << "mm\" height=\"" << sheet.height_mm
      << "mm\" viewBox=\"0 0 " << sheet.width_mm << " " << sheet.height_mm << "\">\n"
      << "<title>ibrdf " << sheet.name << ": print at 100 % (no fit to page)</title>\n"
      << "<rect x=\"0\" y=\"0\" width=\"" << sheet.width_mm << "\" height=\"" << sheet.height_mm
      << "\" fill=\"#ffffff\"/>\n";
  for (const Shape& s : sheet.shapes) {
    const char* fill = s.black ? "#000000" : "#ffffff";
    switch (s.kind) {
      case Shape::Kind::kRect:
        out << "<rect x=\"" << s.x << "\" y=\"" << s.y << "\" width=\"" << s.w << "\" height=\"" << s.h << "\" fill=\""
            << fill << "\" shape-rendering=\"crispEdges\"/>\n";
        break;
      case Shape::Kind::kDisc:
        out << "<circle cx=\"" << s.x << "\" cy=\"" << s.y << "\" r=\"" << s.w << "\" fill=\"" << fill << "\"/>\n";
        break;
      case Shape::Kind::kText:
        out << "<text x=\"" << s.x << "\" y=\"" << s.y << "\" font-family=\"sans-serif\" font-size=\"" << s.h
            << "\" fill=\"" << fill << "\">" << s.text << "</text>\n";
        break;
    }
  }
  out << "</svg>\n";
  return out.str();
}

// The sheet rasterized at `dpi`: each pixel takes the colour at its centre (the last shape covering it);
// text through OpenCV's Hershey font. 8-bit grey, with the resolution in the PNG (pHYs).
void WritePng(const Sheet& sheet, double dpi, const std::string& path) {
  const double px_per_mm = dpi / 25.4;
  const int width = static_cast<int>(std::ceil(sheet.width_mm * px_per_mm));
  const int height = static_cast<int>(std::ceil(sheet.height_mm * px_per_mm));
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(255));
  for (const Shape& s : sheet.shapes) {
    const uint8_t value = s.black ? 0 : 255;
    switch (s.kind) {
      case Shape::Kind::kRect: {
        // Pixels whose centre lies inside: columns ceil(x px - 0.5) .. ceil((x + w) px - 0.5) - 1.
        const int x0 = std::max(0, static_cast<int>(std::ceil(s.x * px_per_mm - 0.5)));
        const int x1 = std::min(width, static_cast<int>(std::ceil((s.x + s.w) * px_per_mm - 0.5)));
        const int y0 = std::max(0, static_cast<int>(std::ceil(s.y * px_per_mm - 0.5)));
        const int y1 = std::min(height, static_cast<int>(std::ceil((s.y + s.h) * px_per_mm - 0.5)));
        if (x1 > x0 && y1 > y0) image(cv::Rect(x0, y0, x1 - x0, y1 - y0)).setTo(value);
        break;
      }
      case Shape::Kind::kDisc: {
        const double cx = s.x * px_per_mm, cy = s.y * px_per_mm, r = s.w * px_per_mm;
        for (int y = std::max(0, int(cy - r - 1)); y < std::min(height, int(cy + r + 2)); ++y) {
          for (int x = std::max(0, int(cx - r - 1)); x < std::min(width, int(cx + r + 2)); ++x) {
            if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= r) image.at<uint8_t>(y, x) = value;
          }
        }
        break;
      }
      case Shape::Kind::kText: {
        const double scale = s.h * px_per_mm / 22.0;  // Hershey simplex: about 22 px tall at scale 1
        cv::putText(image, s.text, cv::Point(int(s.x * px_per_mm), int(s.y * px_per_mm)), cv::FONT_HERSHEY_SIMPLEX,
                    scale, cv::Scalar(value), std::max(1, int(std::lround(scale * 1.5))), cv::LINE_AA);
        break;
      }
    }
  }
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT8);
  spec.attribute("XResolution", static_cast<float>(dpi));
  spec.attribute("YResolution", static_cast<float>(dpi));
  spec.attribute("ResolutionUnit", "in");
  spec.attribute("png:compressionLevel", 6);
  auto output = OIIO::ImageOutput::create(path);
  if (!output || !output->open(path, spec) || !output->write_image(OIIO::TypeDesc::UINT8, image.data) ||
      !output->close()) {
    ThrowError(path, "cannot write the sheet: " + OIIO::geterror());
  }
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) ThrowError(path, "cannot write");
}

// "(fits A4 portrait)" and the like, for the sheet's size.
std::string PaperFor(double width_mm, double height_mm) {
  struct Paper {
    const char* name;
    double w, h;
  };
  for (const Paper& paper :
       {Paper{"A4", 210, 297}, Paper{"A3", 297, 420}, Paper{"A2", 420, 594}, Paper{"A1", 594, 841}}) {
    if (width_mm <= paper.w && height_mm <= paper.h) return std::string("fits ") + paper.name + " portrait";
    if (width_mm <= paper.h && height_mm <= paper.w) return std::string("fits ") + paper.name + " landscape";
  }
  return "larger than A1";
}

std::string Corners(const TargetSpec& target) {
  std::ostringstream out;
  out.precision(4);
  out << std::fixed;
  for (const Eigen::Vector3d& c : target.corners) out << " (" << 1e3 * c.x() << ", " << 1e3 * c.y() << ")";
  return out.str();
}

}  // namespace

bool TargetSheetsOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(ring_count, 3);
  IBRDF_CHECK_OPTION_GT(marker_size, 0.0);
  IBRDF_CHECK_OPTION_GT(ring_radius, 0.0);
  IBRDF_CHECK_OPTION_GE(card_margin, 0.0);
  IBRDF_CHECK_OPTION_GE(light_marker_count, 0);
  IBRDF_CHECK_OPTION(light_marker_count == 0 || light_marker_first_id >= ring_count);
  IBRDF_CHECK_OPTION_GT(light_marker_size, 0.0);
  IBRDF_CHECK_OPTION_GT(light_drop, 0.5 * light_marker_size * (1.0 + 2.0 * card_margin));
  IBRDF_CHECK_OPTION_GE(light_offset, 0.0);
  IBRDF_CHECK_OPTION_GE(dpi, 72.0);
  IBRDF_CHECK_OPTION_LE(dpi, 2400.0);
  IBRDF_CHECK_OPTION_GT(scale_bar, 0.0);
  // Neighbouring cards on the ring must not overlap (centres further apart than a card's side), and
  // every card must lie on the platform.
  const double card = marker_size * (1.0 + 2.0 * card_margin);
  const double card_spacing = 2.0 * ring_radius * std::sin(M_PI / ring_count);
  const double card_reach = ring_radius + card / std::sqrt(2.0);
  IBRDF_CHECK_OPTION_GT(card_spacing, card);
  IBRDF_CHECK_OPTION_GE(platform_radius, card_reach);
  IBRDF_CHECK_OPTION_GT(white_marker_size, 0.0);
  IBRDF_CHECK_OPTION_GT(white_patch_size, 0.0);
  IBRDF_CHECK_OPTION_GE(white_patch_thickness, 0.0);
  IBRDF_CHECK_OPTION_GE(white_marker_first_id, 0);
  // The card's ids must not collide with the light's (the ring's: WriteTargetSheets, after the
  // dictionary's range, which a large ring misses first).
  IBRDF_CHECK_OPTION(!white_card || light_marker_count == 0 ||
                     white_marker_first_id >= light_marker_first_id + light_marker_count ||
                     white_marker_first_id + 4 <= light_marker_first_id);
  return true;
}

std::string TargetSheetsResult::BriefReport() const {
  std::ostringstream out;
  out << "targets: " << (written ? std::to_string(files.size()) + " files" : "nothing written");
  for (const std::string& size : sheet_sizes) out << "; " << size;
  return out.str();
}

WhiteReferenceTargetsSpec WhiteCardLayout(int first_id, double marker_size, double patch_size, double margin,
                                          double patch_thickness) {
  WhiteReferenceTargetsSpec card;
  const double half = 0.5 * marker_size;
  const double d = 0.5 * patch_size + margin * marker_size + half;  // marker centres at (+-d, +-d)
  const Eigen::Vector2d centres[4] = {{-d, d}, {d, d}, {d, -d}, {-d, -d}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d c(centres[k].x(), centres[k].y(), -patch_thickness);
    TargetSpec target;
    target.id = first_id + k;
    target.corners = {c + Eigen::Vector3d(-half, half, 0), c + Eigen::Vector3d(half, half, 0),
                      c + Eigen::Vector3d(half, -half, 0), c + Eigen::Vector3d(-half, -half, 0)};
    card.markers.push_back(target);
  }
  return card;
}

TargetsSpec TargetLayout(const TargetSheetsOptions& options) {
  TargetsSpec targets;
  targets.dictionary = options.dictionary;
  const double half = 0.5 * options.marker_size;
  for (int k = 0; k < options.ring_count; ++k) {
    const double angle = 2.0 * M_PI * (k + 0.5) / options.ring_count;
    const Eigen::Vector3d c(options.ring_radius * std::cos(angle), options.ring_radius * std::sin(angle), 0.0);
    TargetSpec target;
    target.id = k;
    // Top-left, top-right, bottom-right, bottom-left of the upright print (y up the print).
    target.corners = {c + Eigen::Vector3d(-half, half, 0), c + Eigen::Vector3d(half, half, 0),
                      c + Eigen::Vector3d(half, -half, 0), c + Eigen::Vector3d(-half, -half, 0)};
    targets.reference.push_back(target);
  }
  if (options.light_marker_count > 0) {
    LightTargetsSpec light;
    light.size = options.light_marker_size;
    const double pitch = options.light_marker_size * (1.0 + 2.0 * options.card_margin);
    for (int k = 0; k < options.light_marker_count; ++k) {
      // The marker frame: x right, y down the print, z into it; the emitter is up the card by
      // light_drop from the row's centre line, at the row's middle, light_offset in front.
      const double dx = pitch * (k - 0.5 * (options.light_marker_count - 1));
      LightMarkerSpec marker;
      marker.id = options.light_marker_first_id + k;
      marker.light_in_marker = Eigen::Vector3d(-dx, -options.light_drop, -options.light_offset);
      light.markers.push_back(marker);
    }
    targets.light = light;
  }
  if (options.white_card) {
    targets.white_reference =
        WhiteCardLayout(options.white_marker_first_id, options.white_marker_size, options.white_patch_size,
                        options.card_margin, options.white_patch_thickness);
  }
  return targets;
}

nlohmann::json TargetsToJson(const TargetsSpec& targets) {
  nlohmann::json reference = nlohmann::json::array();
  for (const TargetSpec& target : targets.reference) {
    nlohmann::json corners = nlohmann::json::array();
    for (const Eigen::Vector3d& c : target.corners) corners.push_back(ToJson(c));
    reference.push_back({{"id", target.id}, {"corners", corners}});
  }
  nlohmann::json json = {{"dictionary", targets.dictionary}, {"reference", reference}};
  if (targets.white_reference) {
    nlohmann::json markers = nlohmann::json::array();
    for (const TargetSpec& target : targets.white_reference->markers) {
      nlohmann::json corners = nlohmann::json::array();
      for (const Eigen::Vector3d& c : target.corners) corners.push_back(ToJson(c));
      markers.push_back({{"id", target.id}, {"corners", corners}});
    }
    json["white_reference"] = {{"markers", markers}};
  }
  if (targets.light) {
    nlohmann::json markers = nlohmann::json::array();
    for (const LightMarkerSpec& m : targets.light->markers) {
      markers.push_back({{"id", m.id}, {"light_in_marker", ToJson(m.light_in_marker)}});
    }
    json["light"] = {{"size", targets.light->size}, {"markers", markers}};
  }
  return json;
}

namespace {

// The layout's ids fit the dictionary and do not collide; the ChArUco board is one OpenCV draws.
void CheckLayout(const TargetSheetsOptions& options, const MarkerDictionary& dictionary) {
  int last_id = options.light_marker_count > 0 ? options.light_marker_first_id + options.light_marker_count - 1
                                               : options.ring_count - 1;
  if (options.white_card) last_id = std::max(last_id, options.white_marker_first_id + 3);
  if (last_id >= dictionary.size()) {
    ThrowError("--dictionary", options.dictionary + " has ids 0 to " + std::to_string(dictionary.size() - 1) +
                                   "; the layout needs id " + std::to_string(last_id));
  }
  if (options.white_card && options.white_marker_first_id < options.ring_count) {
    ThrowError("--white-marker-first-id",
               "the white card's ids " + std::to_string(options.white_marker_first_id) + " to " +
                   std::to_string(options.white_marker_first_id + 3) + " collide with the ring's 0 to " +
                   std::to_string(options.ring_count - 1) + " (pass another first id, or --no-white-card)");
  }
  if (options.charuco) {
    const CharucoBoardSpec& board = options.board;
    if (!(board.marker_size < board.square_size) || board.squares_y % 2 == 0 || board.squares_x < 3) {
      ThrowError("ChArUco board", "needs marker_size < square_size, an odd number of rows and 3 columns or more");
    }
  }
}

// The platform: the black disc with the ring of reference markers, the sample's cross at the world origin.
Sheet PlatformSheet(const TargetSheetsOptions& options, const MarkerDictionary& dictionary, const TargetsSpec& targets,
                    std::ostringstream* readme) {
  const double r_mm = 1e3 * options.platform_radius;
  Sheet sheet;
  sheet.name = "platform";
  sheet.width_mm = std::max(2.0 * r_mm + 20.0, 150.0);
  sheet.height_mm = 2.0 * r_mm + 60.0;
  const double cx = 0.5 * sheet.width_mm, cy = 10.0 + r_mm;
  sheet.Disc(cx, cy, r_mm, true);
  for (const TargetSpec& target : targets.reference) {
    const Eigen::Vector3d c = 0.25 * (target.corners[0] + target.corners[1] + target.corners[2] + target.corners[3]);
    DrawMarker(dictionary, target.id, cx + 1e3 * c.x(), cy - 1e3 * c.y(), 1e3 * options.marker_size,
               options.card_margin, &sheet);
  }
  // Where the sample rests: a thin white cross at the centre (the world origin).
  sheet.Cross(cx, cy, 4.0, 0.4, false);
  const double text_y = cy + r_mm + 10.0;
  DrawScaleBar(10.0, text_y, 1e3 * options.scale_bar, &sheet);
  sheet.Text(10.0, text_y + 14.0, 3.5,
             options.dictionary + " markers " + Mm(1e3 * options.marker_size) + " (border included), centres " +
                 Mm(1e3 * options.ring_radius) + " from the cross");
  sheet.Text(10.0, text_y + 20.0, 3.5,
             "platform " + Mm(2e3 * options.platform_radius) + " across; sample on the cross");
  sheet.Text(10.0, text_y + 26.0, 3.5, "world frame: origin at the cross, x right, y up this sheet, z up");
  *readme << "platform.svg/.png: lay it flat under the sample, the sample on the white cross at its centre. The\n"
          << "  black disc keeps the sphere's silhouette against black; keep it matte and free of dust.\n"
          << "  Markers " << options.dictionary << ", side " << Mm(1e3 * options.marker_size) << ", centres "
          << Mm(1e3 * options.ring_radius) << " from the centre. Corners (mm, x right, y up the sheet):\n";
  for (const TargetSpec& target : targets.reference) {
    *readme << "    id " << target.id << ":" << Corners(target) << "\n";
  }
  return sheet;
}

// The light card: a row of markers below the light's emitter.
Sheet LightCardSheet(const TargetSheetsOptions& options, const MarkerDictionary& dictionary,
                     std::ostringstream* readme) {
  const double side = 1e3 * options.light_marker_size;
  const double pitch = side * (1.0 + 2.0 * options.card_margin);
  const double drop = 1e3 * options.light_drop;
  Sheet sheet;
  sheet.name = "light-card";
  sheet.width_mm = std::max(pitch * options.light_marker_count + 20.0, 150.0);
  sheet.height_mm = drop + 0.5 * pitch + 60.0;
  const double cx = 0.5 * sheet.width_mm, row_y = 15.0 + drop;
  sheet.Cross(cx, row_y - drop, 8.0, 0.5, true);
  sheet.Text(cx + 10.0, row_y - drop + 1.5, 3.5, "the light's emitter here");
  for (int k = 0; k < options.light_marker_count; ++k) {
    const double dx = pitch * (k - 0.5 * (options.light_marker_count - 1));
    DrawMarker(dictionary, options.light_marker_first_id + k, cx + dx, row_y, side, options.card_margin, &sheet);
  }
  const double text_y = row_y + 0.5 * pitch + 12.0;
  DrawScaleBar(10.0, text_y, std::min(1e3 * options.scale_bar, sheet.width_mm - 20.0), &sheet);
  sheet.Text(10.0, text_y + 14.0, 3.5,
             "markers " + Mm(side) + ", centres " + Mm(pitch) + " apart, " + Mm(drop) + " below the cross");
  *readme << "\nlight-card.svg/.png: fix it upright to the light, facing the sample, the emitter at the cross";
  if (options.light_offset > 0.0) *readme << " and " << Mm(1e3 * options.light_offset) << " in front of the card";
  *readme << ".\n  Take 3 or more photos (role \"targets\") that see it and the platform's ring: `ibrdf align` then\n"
          << "  finds the light (targets.light in targets.json: the emitter in each marker's frame).\n";
  return sheet;
}

// The white reference's card: four markers around the patch's corner marks.
Sheet WhiteCardSheet(const TargetSheetsOptions& options, const MarkerDictionary& dictionary, const TargetsSpec& targets,
                     std::ostringstream* readme) {
  const double side = 1e3 * options.white_marker_size, patch = 1e3 * options.white_patch_size;
  const double card = patch + 2.0 * side * (1.0 + 2.0 * options.card_margin);
  Sheet sheet;
  sheet.name = "white-card";
  sheet.width_mm = std::max(card + 20.0, 190.0);  // room for the captions
  sheet.height_mm = card + 70.0;
  const double cx = 0.5 * sheet.width_mm, cy = 10.0 + 0.5 * card;
  // The card's outline (cut along it), thin.
  const double line = 0.2, h = 0.5 * card;
  sheet.Rect(cx - h, cy - h, card, line, true);
  sheet.Rect(cx - h, cy + h - line, card, line, true);
  sheet.Rect(cx - h, cy - h, line, card, true);
  sheet.Rect(cx + h - line, cy - h, line, card, true);
  for (const TargetSpec& target : targets.white_reference->markers) {
    const Eigen::Vector3d c = 0.25 * (target.corners[0] + target.corners[1] + target.corners[2] + target.corners[3]);
    DrawMarker(dictionary, target.id, cx + 1e3 * c.x(), cy - 1e3 * c.y(), side, 0.0, &sheet);
  }
  // The patch's corners: small L marks 1.5 mm outside it.
  const double p = 0.5 * patch + 1.5, arm = 4.0, w = 0.3;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      // The corner at (x, y); its arms point away from the patch.
      const double x = cx + sx * p, y = cy + sy * p;
      sheet.Rect(std::min(x, x + sx * arm), y - 0.5 * w, arm, w, true);
      sheet.Rect(x - 0.5 * w, std::min(y, y + sy * arm), w, arm, true);
    }
  }
  const double text_y = cy + h + 12.0;
  DrawScaleBar(10.0, text_y, std::min(1e3 * options.scale_bar, sheet.width_mm - 20.0), &sheet);
  sheet.Text(10.0, text_y + 14.0, 3.5, "white patch " + Mm(patch) + " square inside the corner marks");
  sheet.Text(10.0, text_y + 20.0, 3.5,
             "markers " + Mm(side) + ", ids " + std::to_string(options.white_marker_first_id) + " to " +
                 std::to_string(options.white_marker_first_id + 3));
  sheet.Text(10.0, text_y + 26.0, 3.5,
             "patch surface " + Mm(1e3 * options.white_patch_thickness) + " in front of the card");
  *readme << "\nwhite-card.svg/.png: glue it flat to a rigid board and mount the white reference (Spectralon, "
          << Mm(patch) << "\n  square) inside the corner marks";
  if (options.white_patch_thickness > 0.0) {
    *readme << ", its surface " << Mm(1e3 * options.white_patch_thickness) << " in front of the card";
  } else {
    *readme << ", its surface flush with the card (or rerun with --white-patch-thickness-mm)";
  }
  *readme << ".\n  Stand it where the sample was, facing between the light and the camera, and photograph it so\n"
          << "  that the card's 4 markers and 2 or more platform markers are in view: `ibrdf align` then poses it\n"
          << "  (targets.white_reference: the markers' corners in the card's frame, origin at the patch's\n"
          << "  centre, x right, y up, z out of the patch). Corners (mm):\n";
  for (const TargetSpec& target : targets.white_reference->markers) {
    *readme << "    id " << target.id << ":" << Corners(target) << "\n";
  }
  return sheet;
}

// The ChArUco board for the camera's calibration, drawn by OpenCV and traced into rectangles.
Sheet CharucoSheet(const TargetSheetsOptions& options, std::ostringstream* readme) {
  const CharucoBoardSpec& board = options.board;
  const double square = 1e3 * board.square_size;
  Sheet sheet;
  sheet.name = "charuco";
  const double board_w = square * board.squares_x, board_h = square * board.squares_y;
  sheet.width_mm = board_w + 2.0 * std::max(0.5 * square, 10.0);
  sheet.height_mm = board_h + 2.0 * std::max(0.5 * square, 10.0) + 30.0;
  const double x0 = 0.5 * (sheet.width_mm - board_w), y0 = std::max(0.5 * square, 10.0);
  // OpenCV's drawing, at a texel size that puts every square and marker-module edge on a texel edge.
  int texels = 0;
  const double module_mm = 1e3 * board.marker_size / MarkerDictionary(board.dictionary, "board").modules();
  const double inset_mm = 0.5 * (square - 1e3 * board.marker_size);
  for (int t = 8; t <= 1024 && texels == 0; ++t) {
    const double texel = square / t;
    auto aligned = [&](double length) { return std::abs(length / texel - std::round(length / texel)) < 1e-6; };
    if (aligned(module_mm) && aligned(inset_mm)) texels = t;
  }
  if (texels == 0) texels = 400;  // no exact grid: edges within a quarter of a 0.06 mm texel
  int width = 0, height = 0;
  const std::vector<uint8_t> texture = DrawCharucoBoard(board, texels, &width, &height);
  const double texel = square / texels;
  // Runs of black texels per row; identical consecutive rows merge into one rectangle.
  std::vector<std::pair<int, int>> previous, runs;
  int run_start_row = 0;
  auto flush = [&](int end_row) {
    for (const auto& [a, b] : previous) {
      sheet.Rect(x0 + a * texel, y0 + run_start_row * texel, (b - a) * texel, (end_row - run_start_row) * texel, true);
    }
  };
  for (int row = 0; row <= height; ++row) {
    runs.clear();
    if (row < height) {
      for (int col = 0; col < width;) {
        if (texture[size_t(row) * width + col] != 0) {
          ++col;
          continue;
        }
        int end = col;
        while (end < width && texture[size_t(row) * width + end] == 0) ++end;
        runs.emplace_back(col, end);
        col = end;
      }
    }
    if (row == height || runs != previous) {
      flush(row);
      previous = runs;
      run_start_row = row;
    }
  }
  const double text_y = y0 + board_h + 12.0;
  DrawScaleBar(10.0, text_y, std::min(1e3 * options.scale_bar, sheet.width_mm - 20.0), &sheet);
  sheet.Text(10.0, text_y + 14.0, 3.5,
             "ChArUco " + std::to_string(board.squares_x) + " x " + std::to_string(board.squares_y) + ", squares " +
                 Mm(square) + ", markers " + Mm(1e3 * board.marker_size) + " " + board.dictionary);
  *readme << "\ncharuco.svg/.png and board.json: glue the board flat to something rigid; take 12 or more photos of\n"
          << "  it with the measurement's focus and zoom, filling the frame, tilted up to 45 degrees, reaching the\n"
          << "  corners; put them in a folder with board.json and pass it to `ibrdf align --calibrate DIR`.\n";
  return sheet;
}

}  // namespace

TargetSheetsResult WriteTargetSheets(const TargetSheetsOptions& options, const std::string& out_dir) {
  std::string why;
  if (!options.Check(&why)) ThrowError("targets options", why);
  const MarkerDictionary dictionary(options.dictionary, "--dictionary");
  CheckLayout(options, dictionary);
  TargetSheetsResult result;
  result.targets = TargetLayout(options);
  AtomicDirectory directory(out_dir, options.overwrite);
  const std::string tmp = directory.temporary_path();
  auto emit = [&](const Sheet& sheet) {
    WriteText((fs::path(tmp) / (sheet.name + ".svg")).string(), Svg(sheet));
    WritePng(sheet, options.dpi, (fs::path(tmp) / (sheet.name + ".png")).string());
    result.files.push_back(sheet.name + ".svg");
    result.files.push_back(sheet.name + ".png");
    result.sheet_sizes.push_back(sheet.name + ": " + Mm(sheet.width_mm) + " x " + Mm(sheet.height_mm) + " (" +
                                 PaperFor(sheet.width_mm, sheet.height_mm) + ")");
  };
  std::ostringstream readme;
  readme << "ibrdf targets: print every sheet at 100 % (no \"fit to page\"), on matte paper, then measure each\n"
         << "scale bar with a ruler: if it is not the stated length, the printer scaled the sheet: reprint, or\n"
         << "scale every length in targets.json by measured / stated. SVG files are exact (vector); the PNGs\n"
         << "are " << options.dpi << " dpi with the resolution stored in the file.\n\n";
  emit(PlatformSheet(options, dictionary, result.targets, &readme));
  if (result.targets.light) emit(LightCardSheet(options, dictionary, &readme));
  if (result.targets.white_reference) emit(WhiteCardSheet(options, dictionary, result.targets, &readme));
  if (options.charuco) {
    emit(CharucoSheet(options, &readme));
    WriteJsonFile((fs::path(tmp) / "board.json").string(), options.board.ToJson());
    result.files.push_back("board.json");
  }
  WriteJsonFile((fs::path(tmp) / "targets.json").string(),
                {{"format", "ibrdf-targets"}, {"version", 1}, {"targets", TargetsToJson(result.targets)}});
  result.files.push_back("targets.json");
  readme << "\ntargets.json: the session's \"targets\" block; pass it to `ibrdf session init --targets`.\n";
  WriteText((fs::path(tmp) / "README.txt").string(), readme.str());
  result.files.push_back("README.txt");
  directory.Commit();
  result.written = true;
  return result;
}

}  // namespace ibrdf
