// Exposure advice: how much of the BRDF domain each channel failed to measure, per
// band of theta_h (the half vector's angle from the normal, which orders a glossy sample from the
// highlight core outwards), and what to change at capture when clipping or the signal floor removes a
// region: exposure brackets, a longer or shorter exposure, a brighter or differently coloured light.
// The derenderer tallies every pixel that passes the geometric tests (lit, not grazing, not masked);
// the warnings go to the log, the samples' sidecar and `ibrdf run`'s summary.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace ibrdf {

struct ExposureAdviceOptions {
  // A channel's clipped pixels are reported where they exceed this fraction of a theta_h band's
  // pixels (a clipped highlight core is a small area of the photo but the whole peak of the BRDF).
  double max_saturated_fraction = 0.01;
  // A channel's pixels under the signal floor are reported where they exceed this fraction of a band.
  double max_below_signal_fraction = 0.05;
  // Bands with fewer examined pixels than this are not judged (too few to speak of a region).
  uint64_t min_band_pixels = 100;

  bool Check(std::string* why) const;
};

// Per theta_h band (kBandDeg wide, from 0 to 90 degrees) and channel: the pixels examined and those a
// channel lost to clipping, to the signal floor and to non-finite values.
struct ExposureTally {
  static constexpr int kBands = 9;
  static constexpr double kBandDeg = 10.0;
  std::array<uint64_t, kBands> pixels{};
  std::array<std::array<uint64_t, 3>, kBands> saturated{};
  std::array<std::array<uint64_t, 3>, kBands> below_signal{};
  std::array<std::array<uint64_t, 3>, kBands> non_finite{};

  // Counts one pixel at half-vector angle theta_h (radians) with per-channel PixelFlag bits
  // (radiometry/radiance_image.h; 0 = the channel is measured).
  void Add(double theta_h, const uint8_t channel_flags[3]);
  void Merge(const ExposureTally& other);
  // Pixels of all bands.
  uint64_t TotalPixels() const;
};

// One warning: a channel that lost a contiguous range of theta_h bands to one cause.
struct ExposureWarning {
  int channel = 0;    // 0 red, 1 green, 2 blue
  std::string cause;  // "saturated" or "below_signal"
  double theta_h_min_deg = 0.0, theta_h_max_deg = 0.0;
  double worst_fraction = 0.0;  // the largest fraction lost in one band of the range
  uint64_t pixels_lost = 0;     // over the range
  std::string message;          // the full sentence, the remedy named
};

// The warnings of a tally. `bracketed`: the session already has exposure brackets (the remedy for
// clipping is then shorter exposures in them, for the floor longer ones).
std::vector<ExposureWarning> AdviseExposure(const ExposureTally& tally, const ExposureAdviceOptions& options,
                                            bool bracketed);

// The sidecar's "exposure" block: band edges, per-band counts and fractions per channel, the warnings.
nlohmann::json ExposureJson(const ExposureTally& tally, const std::vector<ExposureWarning>& warnings);

}  // namespace ibrdf
