// The radiometric half of derendering: a photo's file values to radiance (docs/radiometry.md). Each
// step follows the session's radiometry block (docs/session-format.md): the response inverted, the
// black level subtracted, divided by exposure time and gain and by the flat field; each pixel flagged
// where it cannot be measured (clipped, not finite, below the signal floor), with a one-sigma
// uncertainty from the camera's noise model. The exposures of one pose (a bracket) are merged into one
// high-dynamic-range radiance image, inverse-variance weighted. The geometric half (rays, hits,
// normals, irradiance) lives in derenderer.cc.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/image_io.h"
#include "core/session.h"

namespace ibrdf {

// Per-pixel flags of a RadianceImage (bits; 0 = measurable). As per-pixel flags (`flags`) they tell
// whether all three channels are measurable, each tested on the pixel's own values; as per-channel
// flags (`channel_flags`) they tell one channel's reason, the floor tested on the expected signal
// (RadianceReader::ReadWindow).
enum PixelFlag : uint8_t {
  kPixelNonFinite = 1,    // a channel is NaN or infinite in the file (in every exposure of a bracket)
  kPixelSaturated = 2,    // a channel reached the saturation level (in every exposure of a bracket)
  kPixelBelowSignal = 4,  // the darkest channel's linear signal is below the floor (in every exposure)
};

// Neighbourhood of the expected signal behind the per-channel signal floor: the ring of the 5x5 pixels
// around a pixel without its inner 3x3 (16 pixels, fewer at the photo's edge), whose noise is
// independent of the pixel's own (even after a bilinear demosaic), so selecting on it does not bias
// the kept values (docs/decisions.md, "Per-channel validity").
constexpr int kFloorRingOuter = 2;  // half-width of the outer square
constexpr int kFloorRingInner = 1;  // half-width of the inner square left out

struct RadianceImage {
  int width = 0;
  int height = 0;
  // 3 floats per pixel, row-major: linear signal / (exposure_s * gain * flat field), in the session's
  // radiance unit; for a bracket, the inverse-variance weighted mean of its usable exposures.
  std::vector<float> radiance;
  // 3 floats per pixel: one standard deviation of radiance from the camera noise model (0 without one).
  std::vector<float> sigma;
  std::vector<uint8_t> flags;  // one per pixel, PixelFlag bits (all three channels, own values)
  // 3 per pixel, PixelFlag bits of each channel alone (0: the channel is measured). The signal floor
  // is tested on the channel's expected signal, the mean over the kFloorRing* ring around the pixel in
  // the same exposure, not on its own noisy value; a merged radiance below 0 is flagged below the floor.
  // radiance and sigma of a flagged channel are not measurements (sigma 0).
  std::vector<uint8_t> channel_flags;
  // Per pixel, how many exposures of the bracket were merged (0 where flagged). Filled for brackets of
  // more than one photo only (empty otherwise).
  std::vector<uint8_t> exposures_used;
  // Per pixel, 0 where the photos' masks exclude it, 1 where usable (photo_mask.h); empty: no mask.
  std::vector<uint8_t> mask;
  // Working memory of RadianceReader::ReadWindow (the expected-signal pass), kept so that a buffer
  // reused from photo to photo allocates it once; holds nothing a caller reads.
  std::vector<float> scratch;

  size_t Index(int x, int y) const { return size_t(y) * width + x; }
};

// A rectangle of pixels [x0, x1) x [y0, y1) (the part of a photo that can see the sample).
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// The photos to derender, grouped by pose and light: measurement photos with the same `bracket` id
// form one group (an exposure bracket; their poses must agree to 1 mm and 0.06 degrees, and their
// light must be the same); measurement photos without a bracket id form one group per distinct
// camera_from_world and light (identical poses under one light are a bracket; under different lights
// they are separate measurements); a photo without a pose is a group of its own. Alignment-only
// photos (role "targets") are in no group. Groups are ordered by their first photo. A bracket's photos
// must differ in exposure (exposure_s x gain): two photos of one pose, one light and one exposure are
// never averaged. Throws Error naming the manifest's photo (and, for a repeated exposure, both files)
// for a bracket whose poses or lights disagree, a repeated exposure, or more than 255 exposures.
std::vector<std::vector<size_t>> ExposureGroups(const Session& session);

// One pixel's reading as a RadianceImage holds it: radiance, sigma and PixelFlag bits per channel, and
// the exposures merged (1 for a single photo).
struct PixelRadiance {
  float radiance[3];
  float sigma[3];
  uint8_t channel_flags[3];
  uint8_t exposures;
};

class RadianceWindow;

// The session's radiometric chain, prepared once (response lookup table, flat field) and applied to
// any number of photos, from any number of threads.
class RadianceReader {
 public:
  // Reads and checks the flat field (size against the camera, positive finite values); throws Error
  // naming the file.
  explicit RadianceReader(const Session& session);
  ~RadianceReader();

  // Decodes the exposures of one pose (paths resolved against the session folder) and merges them
  // into one radiance image. `min_signal` is the signal floor in linear normalized file units
  // (DerenderOptions::min_signal). `decode_s`, when given, gets the seconds spent decoding files added.
  // Throws Error naming the photo for an unreadable or mis-sized file.
  RadianceImage Read(const std::vector<PhotoSpec>& exposures, double min_signal, double* decode_s = nullptr) const;

  // As Read, into buffers reused from photo to photo (the derenderer's loop): `decoded` holds the
  // decoded files (their pixels inside `window` only: core/image_io.h, ReadImageRegion) and `out` the
  // radiance image, both resized only when the camera's size changes.
  // Only the pixels inside `window` are linearized and merged; outside it `out` keeps whatever it
  // held, so the caller must read nothing there. Within the window the values are those of Read.
  void ReadWindow(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
                  std::vector<Image>* decoded, RadianceImage* out, double* decode_s = nullptr) const;

  // As ReadWindow, but each pixel is merged only when asked for (RadianceWindow::At): decodes the
  // exposures and computes, inside `window`, what the merge reads of the neighbours (the expected
  // signal of the floor). `out`'s buffers are reused from photo to photo; `out` keeps a pointer to
  // this reader, which must outlive its use.
  void PrepareWindow(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
                     RadianceWindow* out, double* decode_s = nullptr) const;

  // The linear signal of a file value (response inverted, black level subtracted), through a lookup
  // table for values in [1/64, 1] (exact for linear responses; within 3e-5 relative otherwise).
  double Linear(double encoded) const;

 private:
  friend class RadianceWindow;
  struct Impl;
  struct Exposures;
  // Decodes and checks the exposures into `decoded` and fills `state`'s per-exposure scale and
  // saturation level.
  void Decode(const std::vector<PhotoSpec>& exposures, const PixelWindow& window, std::vector<Image>* decoded,
              Exposures* state, double* decode_s) const;
  // Decodes and checks the exposures and fills `state` (the expected signal inside `window`).
  void Prepare(const std::vector<PhotoSpec>& exposures, double min_signal, const PixelWindow& window,
               std::vector<Image>* decoded, std::vector<float>* scratch, Exposures* state, double* decode_s) const;
  std::unique_ptr<Impl> impl_;
};

// The exposures of one pose, decoded and prepared inside a pixel window by RadianceReader::PrepareWindow,
// merged pixel by pixel on demand: the derenderer merges only the pixels whose ray hits the sample
// (lit, not grazing), instead of every pixel of the window into full-frame radiance and sigma images.
class RadianceWindow {
 public:
  RadianceWindow();
  ~RadianceWindow();
  RadianceWindow(const RadianceWindow&) = delete;
  RadianceWindow& operator=(const RadianceWindow&) = delete;

  // The reading of pixel (x, y), which must lie inside the window: the values RadianceReader::ReadWindow
  // stores for it (RadianceImage's radiance, sigma, channel_flags and exposures_used), bit for bit.
  void At(int x, int y, PixelRadiance* out) const;

  // The photo's size and the window prepared.
  int width() const;
  int height() const;
  const PixelWindow& window() const;

  // Per pixel of the photo, 0 where the photos' masks exclude it (photo_mask.h); empty: no mask. Set by
  // the caller, as RadianceImage::mask.
  std::vector<uint8_t> mask;

 private:
  friend class RadianceReader;
  std::vector<Image> decoded_;
  std::vector<float> scratch_;
  std::unique_ptr<RadianceReader::Exposures> state_;
};

// Decodes the photos of one group (session.photos indices) and turns them into one radiance image,
// as RadianceReader(session).Read(...) does (the flat field is read once per process and file).
RadianceImage ReadRadianceImage(const Session& session, const std::vector<size_t>& group, double min_signal,
                                double* decode_s = nullptr);

}  // namespace ibrdf
