#include "synth/noise_random.h"

#include <array>
#include <cmath>

namespace ibrdf {
namespace {

// The ziggurat of the standard normal's density f(x) = exp(-x^2 / 2) (unnormalized) in kLayers layers
// of equal area kArea: layer i (0 < i < kLayers) is the rectangle [0, x[i]] x [f(x[i]), f(x[i + 1])]; layer
// 0 is the base strip [0, x[0]] x [0, f(r)] of the same area, which holds the tail beyond r = x[1].
constexpr int kLayers = 256;
constexpr double kR = 3.6541528853610088;   // the base strip's right edge, Marsaglia and Tsang's r for 256
constexpr double kArea = 4.92867323399e-3;  // each layer's area, their v for 256 layers

double Density(double x) { return std::exp(-0.5 * x * x); }

struct Ziggurat {
  std::array<double, kLayers + 1> x;  // layer edges, decreasing; x[kLayers] = 0
  std::array<double, kLayers + 1> f;  // Density(x[i])

  Ziggurat() {
    x[0] = kArea / Density(kR);
    x[1] = kR;
    for (int i = 2; i < kLayers; ++i) x[i] = std::sqrt(-2.0 * std::log(Density(x[i - 1]) + kArea / x[i - 1]));
    x[kLayers] = 0.0;
    for (int i = 0; i <= kLayers; ++i) f[i] = Density(x[i]);
  }
};

const Ziggurat& Table() {
  static const Ziggurat table;
  return table;
}

}  // namespace

NoiseRandom::NoiseRandom(uint64_t seed, uint64_t stream, uint64_t row)
    : state_(Mix(Mix(Mix(seed ^ 0x6A09E667F3BCC909ull) ^ stream) + row)) {}

double NoiseRandom::Normal() {
  const Ziggurat& z = Table();
  while (true) {
    const uint64_t bits = (*this)();
    const int layer = int(bits & 0xFF);
    const double sign = (bits & 0x100) ? -1.0 : 1.0;
    const double u = double(bits >> 11) * 0x1.0p-53;  // [0, 1), independent of the low 9 bits
    const double x = u * z.x[layer];
    if (x < z.x[layer + 1]) return sign * x;  // inside the layer's core, under the curve
    if (layer == 0) {
      // The tail beyond r (Marsaglia 1964): r + a with a ~ exponential, accepted with exp(-a^2 / 2).
      double a, b;
      do {
        a = -std::log1p(-Uniform()) / kR;
        b = -std::log1p(-Uniform());
      } while (2.0 * b < a * a);
      return sign * (kR + a);
    }
    // The wedge between the core and the curve.
    if (z.f[layer] + Uniform() * (z.f[layer + 1] - z.f[layer]) < Density(x)) return sign * x;
  }
}

}  // namespace ibrdf
