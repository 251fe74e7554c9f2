// The random numbers of the synthetic sensor (synthetic_radiometry.h): a counter-based stream per
// (seed, stream, row) and exact standard normal deviates by the ziggurat method (Marsaglia and Tsang,
// "The Ziggurat Method for Generating Random Variables", J. Stat. Softw. 5(8), 2000), about ten times
// faster than std::normal_distribution on a Mersenne twister. A row's numbers depend only on its key,
// so an image's noise does not depend on the thread count or the order rows are drawn in.
#pragma once

#include <cstdint>
#include <limits>

namespace ibrdf {

// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014):
// the i-th number of a stream is a bijective mix of key + i * golden, a counter-based generator whose
// streams are keyed by a hash of (seed, stream, row). Meets UniformRandomBitGenerator, so the standard
// distributions (std::poisson_distribution) draw from it too.
class NoiseRandom {
 public:
  using result_type = uint64_t;

  // The stream of (seed, stream, row): three 64-bit words hashed into the counter's start.
  NoiseRandom(uint64_t seed, uint64_t stream, uint64_t row);

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<result_type>::max(); }

  // The next 64 random bits.
  result_type operator()() {
    state_ += 0x9E3779B97F4A7C15ull;
    return Mix(state_);
  }

  // Uniform in [0, 1): the top 53 bits.
  double Uniform() { return double((*this)() >> 11) * 0x1.0p-53; }

  // A standard normal deviate (mean 0, variance 1), exact: the ziggurat of 256 layers, with Marsaglia's
  // tail method beyond r = 3.654; about 1.6 % of draws need an exp(), 0.03 % the tail.
  double Normal();

  // SplitMix64's finalizer (a bijection of 64-bit words).
  static uint64_t Mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

 private:
  uint64_t state_;
};

}  // namespace ibrdf
