#include "calibrate/response_calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/photo.hpp>

#include "calibrate/report_format.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_reader.h"
#include "core/logging.h"
#include "core/statistics.h"
#include "radiometry/radiance_image.h"

namespace ibrdf {
namespace {

constexpr int kLevels = 256;  // OpenCV's calibrations work on 8-bit images (LDR_SIZE)
constexpr int kTopLevel = kLevels - 1;
// The levels of 5-95 % of full scale, where the curve is held to its bounds.
constexpr int kFirstJudgedLevel = 13;  // ceil(0.05 * 255)
constexpr int kLastJudgedLevel = 242;  // floor(0.95 * 255)
// A pixel's exposure is usable evidence between these levels (neither black nor clipped).
constexpr int kLowestUsable = 1, kHighestUsable = 254;

// One exposure of a bracket, read as 8-bit levels.
struct Exposure {
  double time = 0.0;  // exposure_s x gain: only ratios matter
  cv::Mat levels;     // CV_8UC3
};

cv::Mat ReadLevels(const std::string& path) {
  const Image image = ReadImage(path);
  if (image.channels != 3 && image.channels != 1) {
    ThrowError(path, "has " + std::to_string(image.channels) + " channels (a response needs grey or RGB photos)");
  }
  cv::Mat levels(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    cv::Vec3b* row = levels.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = image.at(x, y, image.channels == 3 ? c : 0);
        row[x][c] = static_cast<uint8_t>(std::clamp(std::lround(double(v) * kTopLevel), 0L, long(kTopLevel)));
      }
    }
  }
  return levels;
}

// Whether a level is usable evidence (neither black nor clipped).
bool Usable(uint8_t level) { return level >= kLowestUsable && level <= kHighestUsable; }

// Chooses up to `count` pixels whose channel `c` is usable in at least two exposures, spread evenly
// over that channel's level in the bracket's middle exposure (so that every exposure's levels are
// covered), and lays them out as a k x k single-channel montage per exposure: OpenCV's grid sampling of
// a k x k image with k^2 samples visits every pixel, so the system sees exactly the chosen pixels.
std::vector<cv::Mat> ChooseMontage(const std::vector<Exposure>& exposures, int c, int count, int* pixels) {
  const cv::Mat& middle = exposures[exposures.size() / 2].levels;
  constexpr int kBins = 32;
  std::vector<std::vector<cv::Point>> bins(kBins);
  for (int y = 0; y < middle.rows; ++y) {
    for (int x = 0; x < middle.cols; ++x) {
      int usable = 0;
      for (const Exposure& e : exposures) usable += Usable(e.levels.at<cv::Vec3b>(y, x)[c]);
      if (usable < 2) continue;
      bins[middle.at<cv::Vec3b>(y, x)[c] * kBins / kLevels].push_back(cv::Point(x, y));
    }
  }
  // Round-robin over the bins, each shuffled with a fixed seed: the result depends on the photos only.
  std::mt19937 random(20260601u + c);
  for (std::vector<cv::Point>& bin : bins) std::shuffle(bin.begin(), bin.end(), random);
  std::vector<cv::Point> chosen;
  for (size_t round = 0; static_cast<int>(chosen.size()) < count; ++round) {
    bool any = false;
    for (const std::vector<cv::Point>& bin : bins) {
      if (round < bin.size() && static_cast<int>(chosen.size()) < count) {
        chosen.push_back(bin[round]);
        any = true;
      }
    }
    if (!any) break;
  }
  const int side = static_cast<int>(std::sqrt(double(chosen.size())));
  *pixels = side * side;
  std::vector<cv::Mat> montage;
  for (const Exposure& e : exposures) {
    cv::Mat m(side, side, CV_8UC1);
    for (int i = 0; i < side * side; ++i) m.at<uint8_t>(i / side, i % side) = e.levels.at<cv::Vec3b>(chosen[i])[c];
    montage.push_back(m);
  }
  return montage;
}

// log of a single-channel calibration curve (256 x 1, CV_32F), 0 at the middle level.
std::vector<double> LogCurve(const cv::Mat& response) {
  std::vector<double> curve(kLevels);
  const double anchor = std::log(std::max(double(response.at<float>(kLevels / 2)), 1e-30));
  for (int z = 0; z < kLevels; ++z) curve[z] = std::log(std::max(double(response.at<float>(z)), 1e-30)) - anchor;
  return curve;
}

// One channel of one bracket, calibrated.
struct ChannelCurve {
  int channel = 0;
  std::vector<double> debevec, robertson;  // log curves, aligned to the reference curve once combined
  std::vector<int> hits;                   // per level: the chosen pixels' usable exposures there
  bool Constrained(int z) const { return hits[z] >= ResponseCalibration::kMinLevelHits; }
  int ConstrainedLevels() const {
    int n = 0;
    for (int z = 0; z < kLevels; ++z) n += Constrained(z);
    return n;
  }
};

// The offset that takes `curve` onto `reference` (log units) over the levels both constrain: their
// median difference; false when they share under 8 levels.
bool AlignmentOffset(const std::vector<double>& reference, const ChannelCurve& reference_curve,
                     const std::vector<double>& curve, const ChannelCurve& constraints, double* offset) {
  std::vector<double> differences;
  for (int z = 0; z < kLevels; ++z) {
    if (reference_curve.Constrained(z) && constraints.Constrained(z)) differences.push_back(reference[z] - curve[z]);
  }
  if (differences.size() < 8) return false;
  *offset = Median(differences);
  return true;
}

double RelativeDifference(double log_a, double log_b) { return std::abs(std::expm1(log_a - log_b)); }

}  // namespace

bool ResponseCalibrationOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_GE(pixels_per_bracket, 16);
  IBRDF_CHECK_OPTION_LE(pixels_per_bracket, 4096);
  IBRDF_CHECK_OPTION_GE(smoothness, 0.0);
  IBRDF_CHECK_OPTION_GE(max_brackets, 1);
  return true;
}

ResponseCalibration CalibrateResponse(const Session& session, const ResponseCalibrationOptions& options) {
  std::string why;
  if (!options.Check(&why)) ThrowError("response options", why);
  ResponseCalibration result;
  std::vector<std::vector<size_t>> usable_groups;
  std::vector<size_t> usable_bracket;  // usable_groups[k]'s entry in result.brackets
  for (const std::vector<size_t>& group : ExposureGroups(session)) {
    ResponseBracket bracket;
    bracket.first_photo = session.photos[group.front()].file;
    std::vector<double> times;
    for (size_t i : group) times.push_back(session.photos[i].exposure_s * session.photos[i].gain);
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    bracket.exposures = static_cast<int>(times.size());
    bracket.span_ev = std::log2(times.back() / times.front());
    if (bracket.exposures < 2) {
      bracket.left_out = "one exposure";
    } else {
      usable_groups.push_back(group);
      usable_bracket.push_back(result.brackets.size());
    }
    result.brackets.push_back(bracket);
  }
  if (usable_groups.empty()) {
    ThrowError(session.manifest_path,
               "has no exposure bracket (photos of one pose under one light at two or more exposures): nothing "
               "constrains a response curve; shoot each pose at 3 or more exposures, 1-2 EV apart");
  }
  // Evenly chosen brackets when there are more than the options allow.
  std::vector<size_t> chosen;
  const size_t n = usable_groups.size(), m = std::min<size_t>(n, options.max_brackets);
  for (size_t k = 0; k < m; ++k) chosen.push_back(k * n / m);
  std::vector<ChannelCurve> curves;
  for (size_t k : chosen) {
    const std::vector<size_t>& group = usable_groups[k];
    std::vector<Exposure> exposures;
    for (size_t i : group) {
      const PhotoSpec& photo = session.photos[i];
      exposures.push_back({photo.exposure_s * photo.gain, ReadLevels(session.PhotoPath(i))});
    }
    std::sort(exposures.begin(), exposures.end(), [](const Exposure& a, const Exposure& b) { return a.time < b.time; });
    ResponseBracket* bracket = &result.brackets[usable_bracket[k]];
    std::vector<float> times;
    for (const Exposure& e : exposures) times.push_back(static_cast<float>(e.time));
    const cv::Mat times_mat(times, true);
    int channels_used = 0;
    for (int c = 0; c < 3; ++c) {
      int pixels = 0;
      const std::vector<cv::Mat> montage = ChooseMontage(exposures, c, options.pixels_per_bracket, &pixels);
      if (pixels < 16) continue;
      ChannelCurve curve;
      curve.channel = c;
      cv::Mat debevec;
      cv::createCalibrateDebevec(pixels, static_cast<float>(options.smoothness), false)
          ->process(montage, debevec, times_mat);
      curve.debevec = LogCurve(debevec);
      // Robertson's OpenCV 4.6 code starts from a three-channel curve whatever the images have: it is
      // given the channel three times.
      std::vector<cv::Mat> rgb;
      for (const cv::Mat& plane : montage) {
        cv::Mat three;
        cv::merge(std::vector<cv::Mat>{plane, plane, plane}, three);
        rgb.push_back(three);
      }
      cv::Mat robertson;
      cv::createCalibrateRobertson()->process(rgb, robertson, times_mat);
      cv::Mat first;
      cv::extractChannel(robertson, first, 0);
      curve.robertson = LogCurve(first);
      curve.hits.assign(kLevels, 0);
      for (const cv::Mat& plane : montage) {
        for (int i = 0; i < pixels; ++i) {
          const uint8_t v = plane.at<uint8_t>(i / plane.cols, i % plane.cols);
          if (Usable(v)) ++curve.hits[v];
        }
      }
      curves.push_back(std::move(curve));
      bracket->pixels += pixels;
      result.pixels_used += pixels;
      ++channels_used;
    }
    if (channels_used == 0) {
      bracket->left_out = "no channel has 16 pixels usable (neither black nor clipped) in two exposures";
      continue;
    }
    result.span_ev = std::max(result.span_ev, bracket->span_ev);
    ++result.brackets_used;
  }
  if (curves.empty()) {
    ThrowError(session.manifest_path,
               "no exposure bracket has 16 pixels that are neither black nor clipped in two exposures: nothing "
               "constrains a response curve; expose the brackets so that the scene's mid-tones are seen in several");
  }
  // Every curve is known up to a factor (Debevec's anchor at the middle level, which a dim channel may
  // never reach): each is aligned to the curve that constrains the most levels, over the levels both
  // constrain; one that shares too few is left out.
  size_t reference = 0;
  for (size_t i = 1; i < curves.size(); ++i) {
    if (curves[i].ConstrainedLevels() > curves[reference].ConstrainedLevels()) reference = i;
  }
  const std::vector<double> reference_log = curves[reference].debevec;
  std::vector<ChannelCurve> aligned;
  for (ChannelCurve& curve : curves) {
    double offset = 0.0, robertson_offset = 0.0;
    if (!AlignmentOffset(reference_log, curves[reference], curve.debevec, curve, &offset) ||
        !AlignmentOffset(reference_log, curves[reference], curve.robertson, curve, &robertson_offset)) {
      continue;
    }
    for (int z = 0; z < kLevels; ++z) {
      curve.debevec[z] += offset;
      curve.robertson[z] += robertson_offset;
    }
    aligned.push_back(curve);
  }
  // Per level, the median over the curves that constrain it (a level is constrained when two or more
  // do; elsewhere the median of all, extrapolated), its standard error 1.4826 MAD / sqrt(n) in log
  // units (relative); per channel the same over that channel's curves.
  std::vector<double> combined(kLevels), error(kLevels), robertson_combined(kLevels);
  std::vector<bool> constrained(kLevels, false);
  std::array<std::vector<double>, 3> channel;
  std::array<std::vector<bool>, 3> channel_constrained;
  for (int c = 0; c < 3; ++c) {
    channel[c].assign(kLevels, 0.0);
    channel_constrained[c].assign(kLevels, false);
  }
  for (int z = 0; z < kLevels; ++z) {
    std::vector<double> values, everything, robertson_values;
    std::array<std::vector<double>, 3> per_channel, per_channel_all;
    for (const ChannelCurve& curve : aligned) {
      everything.push_back(curve.debevec[z]);
      per_channel_all[curve.channel].push_back(curve.debevec[z]);
      if (!curve.Constrained(z)) continue;
      values.push_back(curve.debevec[z]);
      robertson_values.push_back(curve.robertson[z]);
      per_channel[curve.channel].push_back(curve.debevec[z]);
    }
    constrained[z] = values.size() >= 2;
    combined[z] = Median(constrained[z] ? values : everything);
    robertson_combined[z] = robertson_values.empty() ? combined[z] : Median(robertson_values);
    std::vector<double> deviation;
    for (double v : values) deviation.push_back(std::abs(v - combined[z]));
    error[z] = constrained[z] ? 1.4826 * Median(deviation) / std::sqrt(double(values.size())) : 0.0;
    for (int c = 0; c < 3; ++c) {
      channel_constrained[c][z] = !per_channel[c].empty();
      if (!per_channel_all[c].empty()) {
        channel[c][z] = Median(channel_constrained[c][z] ? per_channel[c] : per_channel_all[c]);
      }
    }
  }
  result.lowest_level = kTopLevel;
  result.highest_level = 0;
  for (int z = 0; z < kLevels; ++z) {
    if (constrained[z]) {
      result.lowest_level = std::min(result.lowest_level, z);
      result.highest_level = std::max(result.highest_level, z);
    }
  }
  std::vector<double> judged_error;
  int covered = 0;
  for (int z = kFirstJudgedLevel; z <= kLastJudgedLevel; ++z) {
    if (!constrained[z]) continue;
    ++covered;
    judged_error.push_back(error[z]);
    result.max_uncertainty = std::max(result.max_uncertainty, error[z]);
    for (int c = 0; c < 3; ++c) {
      if (!channel_constrained[c][z]) continue;
      result.channel_spread = std::max(result.channel_spread, RelativeDifference(channel[c][z], combined[z]));
    }
    result.robertson_difference =
        std::max(result.robertson_difference, RelativeDifference(robertson_combined[z], combined[z]));
  }
  result.level_coverage = double(covered) / double(kLastJudgedLevel - kFirstJudgedLevel + 1);
  result.median_uncertainty = judged_error.empty() ? 0.0 : Median(judged_error);
  // Judged where the table is held to its bounds (the first levels above black are noise-bound), and
  // only for a fall of over 2 %: where the set of curves that constrain a level changes, the median
  // may step back by a fraction of a level's rise; a moved scene or a misstated exposure falls by more.
  for (int z = std::max(result.lowest_level, kFirstJudgedLevel) + 1; z <= result.highest_level; ++z) {
    if (combined[z - 1] - combined[z] > 0.02 || !std::isfinite(combined[z])) result.monotonic = false;
  }
  // The table: scaled to 1 at full scale, 0 at file value 0 (no light, or below the first level the
  // data reach: such pixels are under the derenderer's signal floor), and kept strictly rising where the
  // smoothness term's extrapolation flattens (the verdict judges the constrained levels only).
  Response& response = result.response;
  response.kind = Response::Kind::kTable;
  response.table.assign(kLevels, 0.0);
  response.uncertainty.assign(kLevels, 0.0);
  // Full scale itself is no evidence (a clipped pixel reads it whatever its light): its value is the
  // log curve carried on from the last two usable levels.
  const double full_scale = 2.0 * combined[kHighestUsable] - combined[kHighestUsable - 1];
  for (int z = 1; z < kLevels; ++z) {
    response.table[z] = std::exp((z == kTopLevel ? full_scale : combined[z]) - full_scale);
    response.uncertainty[z] = error[z];
  }
  for (int z = 1; z < kLevels; ++z) {
    const double floor = response.table[z - 1] * (1.0 + 1e-9) + 1e-12;
    if (!(response.table[z] > response.table[z - 1])) response.table[z] = floor;
  }
  for (int c = 0; c < 3; ++c) {
    result.channel_tables[c].assign(kLevels, 0.0);
    for (int z = 1; z < kLevels; ++z) result.channel_tables[c][z] = std::exp(channel[c][z] - full_scale);
  }
  result.verdicts = ResponseVerdicts(result);
  return result;
}

std::vector<Verdict> ResponseVerdicts(const ResponseCalibration& r) {
  std::vector<Verdict> verdicts;
  verdicts.push_back(
      MakeVerdict("response.brackets", r.brackets_used, std::to_string(r.brackets_used) + " brackets used",
                  "warn under 3", r.brackets_used < 3 ? VerdictLevel::kWarn : VerdictLevel::kOk,
                  "more brackets (poses) average out the noise of each: shoot every pose at 3 or more exposures"));
  verdicts.push_back(MakeVerdict("response.span", r.span_ev, FormatNumbers("%.1f EV between exposures", r.span_ev),
                                 "warn under 4 EV, fail under 2 EV", VerdictBelow(r.span_ev, 4.0, 2.0),
                                 "widen the brackets (e.g. 5 exposures 1.5 EV apart) so that every level is seen "
                                 "together with a much darker and a much brighter exposure"));
  verdicts.push_back(MakeVerdict(
      "response.coverage", r.level_coverage,
      FormatNumbers("%.0f %% of the levels of 5-95 %% of full scale constrained (levels %.0f-%.0f)",
                    100.0 * r.level_coverage, r.lowest_level, r.highest_level),
      "warn under 90 %, fail under 50 %", VerdictBelow(r.level_coverage, 0.9, 0.5),
      "expose the brackets so that the scene spans the range: the longest exposure clipping its highlights, the "
      "shortest showing them"));
  verdicts.push_back(
      MakeVerdict("response.uncertainty", r.median_uncertainty,
                  FormatNumbers("median standard error %.2f %% (worst %.2f %%) over the constrained levels",
                                100.0 * r.median_uncertainty, 100.0 * r.max_uncertainty),
                  "warn over 1 %, fail over 3 %", VerdictAbove(r.median_uncertainty, 0.01, 0.03),
                  "more brackets or more pixels per bracket (--pixels); a static scene and light between exposures"));
  verdicts.push_back(
      MakeVerdict("response.monotonic", r.monotonic ? 1.0 : 0.0,
                  r.monotonic ? "rises over the constrained levels" : "falls somewhere in the constrained levels",
                  "must rise", r.monotonic ? VerdictLevel::kOk : VerdictLevel::kFail,
                  "the scene or light moved between exposures, or the exposures are misstated "
                  "(exposure_s, gain): check the bracket's photos"));
  verdicts.push_back(MakeVerdict(
      "response.channels", r.channel_spread,
      FormatNumbers("channels differ from the combined curve by up to %.2f %%", 100.0 * r.channel_spread),
      "warn over 3 %, fail over 10 % (one curve serves all channels)", VerdictAbove(r.channel_spread, 0.03, 0.10),
      "the camera's channels have different curves: this calibration models one curve for all; use RAW photos"));
  verdicts.push_back(MakeVerdict(
      "response.methods", r.robertson_difference,
      FormatNumbers("Robertson's curve differs from Debevec's by up to %.2f %%", 100.0 * r.robertson_difference),
      "warn over 5 %, fail over 25 %", VerdictAbove(r.robertson_difference, 0.05, 0.25),
      "the two calibrations disagree: more pixels per bracket or wider brackets"));
  return verdicts;
}

std::string ResponseCalibration::BriefReport() const {
  return FormatNumbers("response: 256-level table from %.0f brackets (%.0f pixels, up to %.1f EV), ", brackets_used,
                       pixels_used, span_ev) +
         FormatNumbers("levels %.0f-%.0f constrained (%.0f %% of 5-95 %% full scale), ", lowest_level, highest_level,
                       100.0 * level_coverage) +
         FormatNumbers("standard error %.2f %% median; Robertson within %.2f %%", 100.0 * median_uncertainty,
                       100.0 * robertson_difference);
}

nlohmann::json ResponseCalibration::ToJson() const {
  nlohmann::json brackets_json = nlohmann::json::array();
  for (const ResponseBracket& b : brackets) {
    nlohmann::json j = {{"first_photo", b.first_photo}, {"exposures", b.exposures}, {"span_ev", b.span_ev}};
    if (b.left_out.empty()) {
      j["pixels"] = b.pixels;
    } else {
      j["left_out"] = b.left_out;
    }
    brackets_json.push_back(j);
  }
  return {{"format", "ibrdf-response"},
          {"version", 1},
          {"summary", BriefReport()},
          {"method",
           "Debevec and Malik 1997 (OpenCV createCalibrateDebevec), per bracket, median over brackets "
           "and channels; Robertson (createCalibrateRobertson) as a cross-check"},
          {"levels", kLevels},
          {"table", response.table},
          {"uncertainty", response.uncertainty},
          {"channel_tables", channel_tables},
          {"scale", "1 at full scale (file value 1)"},
          {"constrained_levels", {lowest_level, highest_level}},
          {"extrapolated", "levels outside constrained_levels come from the smoothness term alone"},
          {"level_coverage", level_coverage},
          {"median_uncertainty", median_uncertainty},
          {"max_uncertainty", max_uncertainty},
          {"channel_spread", channel_spread},
          {"robertson_difference", robertson_difference},
          {"brackets_used", brackets_used},
          {"pixels_used", pixels_used},
          {"span_ev", span_ev},
          {"brackets", brackets_json},
          {"verdicts", VerdictsToJson(verdicts)}};
}

void WriteResponseStage(const Session& session, const ResponseCalibration& calibration, const std::string& out_dir,
                        bool overwrite) {
  Session measured = session;
  measured.radiometry.response = calibration.response;
  measured.radiometry.black_level = 0.0;
  AtomicDirectory directory(out_dir, overwrite);
  const std::string folder = directory.temporary_path();
  measured.MarkApplied(SessionStage::kResponse);
  measured.Rebased(out_dir).Save((std::filesystem::path(folder) / "session.json").string());
  nlohmann::json json = calibration.ToJson();
  if (session.radiometry.black_level > 0.0) {
    json["black_level_replaced"] = session.radiometry.black_level;
  }
  WriteJsonFile((std::filesystem::path(folder) / "response.json").string(), json);
  directory.Commit();
}

}  // namespace ibrdf
