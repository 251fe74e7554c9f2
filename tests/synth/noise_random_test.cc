// The synthetic sensor's random numbers (synth/noise_random.h) and the noise statistics of
// SimulateSensor (synth/synthetic_radiometry.h): the ziggurat's deviates are standard normal (moments,
// tail, the distribution function at fixed points), and a flat signal comes out with the mean and
// variance of the shot, read and quantization noise model, whatever the thread count.
#include "synth/noise_random.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/image_io.h"
#include "synth/synthetic_radiometry.h"

namespace ibrdf {
namespace {

TEST(NoiseRandom, StreamsAreDeterministicAndDistinct) {
  NoiseRandom a(1, 2, 3), b(1, 2, 3), c(1, 2, 4), d(2, 2, 3);
  for (int i = 0; i < 100; ++i) {
    const uint64_t x = a();
    EXPECT_EQ(x, b());
    EXPECT_NE(x, c());
    EXPECT_NE(x, d());
  }
}

TEST(NoiseRandom, UniformIsInTheUnitIntervalWithMeanAHalf) {
  NoiseRandom rng(7, 0, 0);
  constexpr int kDraws = 1000000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  const double mean = sum / kDraws;
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / kDraws));
  EXPECT_NEAR(sum2 / kDraws - mean * mean, 1.0 / 12, 1e-3);
}

// The standard normal distribution function.
double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

TEST(NoiseRandom, NormalHasTheStandardNormalsMomentsTailAndDistribution) {
  constexpr int kDraws = 4000000;
  double sum = 0.0, sum2 = 0.0, sum3 = 0.0, sum4 = 0.0;
  const std::vector<double> points = {-3.0, -2.0, -1.0, -0.5, 0.0, 0.25, 1.0, 2.0, 3.0, 3.6541528853610088, 4.0};
  std::vector<size_t> below(points.size(), 0);
  size_t beyond_r = 0;
  for (int row = 0; row < 4; ++row) {
    NoiseRandom rng(11, 5, row);
    for (int i = 0; i < kDraws / 4; ++i) {
      const double z = rng.Normal();
      ASSERT_TRUE(std::isfinite(z));
      sum += z;
      sum2 += z * z;
      sum3 += z * z * z;
      sum4 += z * z * z * z;
      for (size_t k = 0; k < points.size(); ++k) below[k] += z < points[k];
      beyond_r += std::abs(z) > 3.6541528853610088;
    }
  }
  const double n = kDraws;
  // Standard errors: mean 1/sqrt(n), variance sqrt(2/n), skewness sqrt(6/n), kurtosis sqrt(24/n); 5 sigma.
  EXPECT_NEAR(sum / n, 0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(sum2 / n, 1.0, 5 * std::sqrt(2 / n));
  EXPECT_NEAR(sum3 / n, 0.0, 5 * std::sqrt(15 / n));
  EXPECT_NEAR(sum4 / n, 3.0, 5 * std::sqrt(96 / n));
  for (size_t k = 0; k < points.size(); ++k) {
    const double p = Phi(points[k]);
    EXPECT_NEAR(below[k] / n, p, 5 * std::sqrt(p * (1 - p) / n) + 1e-7) << "P(Z < " << points[k] << ")";
  }
  // The tail beyond r (drawn by the tail method): 2 (1 - Phi(r)) = 2.58e-4, about 1000 draws.
  const double tail = 2 * (1 - Phi(3.6541528853610088));
  EXPECT_NEAR(beyond_r / n, tail, 5 * std::sqrt(tail / n));
}

// A flat image of signal `v` through the sensor: the mean and variance of its values.
void FlatStatistics(const CameraEffects& effects, double v, double* mean, double* variance) {
  Image image(400, 300, 3);
  for (float& p : image.pixels) p = static_cast<float>(v);
  SimulateSensor(effects, 3, 9, &image);
  double sum = 0.0, sum2 = 0.0;
  for (const float p : image.pixels) {
    sum += p;
    sum2 += double(p) * p;
  }
  const double n = image.pixels.size();
  *mean = sum / n;
  *variance = sum2 / n - *mean * *mean;
}

TEST(SimulateSensor, FlatSignalHasTheNoiseModelsMeanAndVariance) {
  CameraEffects effects;  // 20000 e- full well, 4 e- read noise, 12 bits, linear, clipped at 1
  const double lsb = 1.0 / 4095.0;
  for (const double v : {0.02, 0.3, 0.7}) {  // 400 e- (Poisson), 6000 and 14000 e- (Gaussian)
    double mean, variance;
    FlatStatistics(effects, v, &mean, &variance);
    const double expected =
        v / effects.full_well_e + std::pow(effects.read_noise_e / effects.full_well_e, 2) + lsb * lsb / 12.0;
    const double n = 400.0 * 300 * 3;
    EXPECT_NEAR(mean, v, 5 * std::sqrt(expected / n) + 1e-6) << "signal " << v;
    EXPECT_NEAR(variance / expected, 1.0, 5 * std::sqrt(2.0 / n) + 0.01) << "signal " << v;
  }
}

TEST(SimulateSensor, ThreadCountChangesNothing) {
  CameraEffects effects;
  Image one(300, 200, 3), two;
  for (size_t i = 0; i < one.pixels.size(); ++i) one.pixels[i] = float(0.001 * (i % 997));
  two = one;
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    SimulateSensor(effects, 1, 2, &one);
  }
  {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
    SimulateSensor(effects, 1, 2, &two);
  }
  EXPECT_EQ(one.pixels, two.pixels);
}

}  // namespace
}  // namespace ibrdf
