#include "radiometry/exposure_advice.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "radiometry/radiance_image.h"

namespace ibrdf {
namespace {

constexpr const char* kChannelNames[3] = {"red", "green", "blue"};

std::string Percent(double fraction) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f %%", 100.0 * fraction);
  return buffer;
}

std::string Remedy(const std::string& cause, int channel, bool bracketed) {
  if (cause == "saturated") {
    return bracketed ? "add shorter exposures to each pose's bracket (or lower the light's power)"
                     : "take exposure brackets (the same pose at shorter exposures, `bracket` in session.json; "
                       "`ibrdf synth --brackets 3` for synthetic sessions) or shorten the exposure";
  }
  std::string remedy = bracketed ? "add longer exposures to each pose's bracket"
                                 : "expose longer, or take exposure "
                                   "brackets with longer exposures";
  remedy += ", or use a brighter light";
  if (channel == 2) remedy += " or a bluer one (the blue channel is the weak one)";
  if (channel == 0) remedy += " or a redder one (the red channel is the weak one)";
  if (channel == 1) remedy += " or one richer in green (the green channel is the weak one)";
  return remedy;
}

}  // namespace

bool ExposureAdviceOptions::Check(std::string* why) const {
  IBRDF_CHECK_OPTION_RANGE(max_saturated_fraction, 0.0, 1.0);
  IBRDF_CHECK_OPTION_RANGE(max_below_signal_fraction, 0.0, 1.0);
  return true;
}

void ExposureTally::Add(double theta_h, const uint8_t channel_flags[3]) {
  const int band = std::clamp(static_cast<int>(theta_h * 180.0 / M_PI / kBandDeg), 0, kBands - 1);
  ++pixels[band];
  for (int c = 0; c < 3; ++c) {
    const uint8_t f = channel_flags[c];
    if (f & kPixelNonFinite) {
      ++non_finite[band][c];
    } else if (f & kPixelSaturated) {
      ++saturated[band][c];
    } else if (f & kPixelBelowSignal) {
      ++below_signal[band][c];
    }
  }
}

void ExposureTally::Merge(const ExposureTally& other) {
  for (int b = 0; b < kBands; ++b) {
    pixels[b] += other.pixels[b];
    for (int c = 0; c < 3; ++c) {
      saturated[b][c] += other.saturated[b][c];
      below_signal[b][c] += other.below_signal[b][c];
      non_finite[b][c] += other.non_finite[b][c];
    }
  }
}

uint64_t ExposureTally::TotalPixels() const {
  uint64_t total = 0;
  for (const uint64_t n : pixels) total += n;
  return total;
}

std::vector<ExposureWarning> AdviseExposure(const ExposureTally& tally, const ExposureAdviceOptions& options,
                                            bool bracketed) {
  std::vector<ExposureWarning> warnings;
  for (const std::string cause : {"saturated", "below_signal"}) {
    const auto& lost = cause == "saturated" ? tally.saturated : tally.below_signal;
    const double limit = cause == "saturated" ? options.max_saturated_fraction : options.max_below_signal_fraction;
    for (int c = 0; c < 3; ++c) {
      // Runs of consecutive bands over the limit, each one warning.
      for (int b = 0; b < ExposureTally::kBands;) {
        const auto over = [&](int k) {
          return tally.pixels[k] >= options.min_band_pixels && lost[k][c] > limit * double(tally.pixels[k]);
        };
        if (!over(b)) {
          ++b;
          continue;
        }
        ExposureWarning w;
        w.channel = c;
        w.cause = cause;
        w.theta_h_min_deg = b * ExposureTally::kBandDeg;
        uint64_t pixels = 0;
        int end = b;
        for (; end < ExposureTally::kBands && over(end); ++end) {
          w.pixels_lost += lost[end][c];
          pixels += tally.pixels[end];
          w.worst_fraction = std::max(w.worst_fraction, double(lost[end][c]) / double(tally.pixels[end]));
        }
        w.theta_h_max_deg = end * ExposureTally::kBandDeg;
        char range[96];
        std::snprintf(range, sizeof(range), "theta_h %.0f-%.0f deg", w.theta_h_min_deg, w.theta_h_max_deg);
        w.message = std::string("exposure: the ") + kChannelNames[c] + " channel " +
                    (cause == "saturated" ? "is clipped" : "is below the signal floor") + " in " +
                    Percent(double(w.pixels_lost) / double(pixels)) + " of the pixels at " + range + " (" +
                    std::to_string(w.pixels_lost) + " pixels, up to " + Percent(w.worst_fraction) +
                    " of one 10-degree band): " +
                    (cause == "saturated" ? "the highlight there is not measured in that channel"
                                          : "that region of the BRDF is not measured in that channel") +
                    "; remedy: " + Remedy(cause, c, bracketed);
        warnings.push_back(std::move(w));
        b = end;
      }
    }
  }
  return warnings;
}

nlohmann::json ExposureJson(const ExposureTally& tally, const std::vector<ExposureWarning>& warnings) {
  nlohmann::json bands = nlohmann::json::array();
  for (int b = 0; b < ExposureTally::kBands; ++b) {
    const double n = double(std::max<uint64_t>(tally.pixels[b], 1));
    nlohmann::json band = {{"theta_h_deg", {b * ExposureTally::kBandDeg, (b + 1) * ExposureTally::kBandDeg}},
                           {"pixels", tally.pixels[b]},
                           {"saturated", tally.saturated[b]},
                           {"below_signal", tally.below_signal[b]},
                           {"non_finite", tally.non_finite[b]}};
    nlohmann::json lost = nlohmann::json::array();
    for (int c = 0; c < 3; ++c) {
      lost.push_back(double(tally.saturated[b][c] + tally.below_signal[b][c] + tally.non_finite[b][c]) / n);
    }
    band["fraction_lost"] = lost;
    bands.push_back(band);
  }
  nlohmann::json list = nlohmann::json::array();
  for (const ExposureWarning& w : warnings) {
    list.push_back({{"channel", kChannelNames[w.channel]},
                    {"cause", w.cause},
                    {"theta_h_deg", {w.theta_h_min_deg, w.theta_h_max_deg}},
                    {"worst_fraction", w.worst_fraction},
                    {"pixels_lost", w.pixels_lost},
                    {"message", w.message}});
  }
  return {{"what",
           "per theta_h band, the pixels that passed the geometric tests and, per channel (R, G, B), those clipped, "
           "under the signal floor or not finite (a pixel is kept while any channel is measured)"},
          {"bands", bands},
          {"warnings", list}};
}

}  // namespace ibrdf
