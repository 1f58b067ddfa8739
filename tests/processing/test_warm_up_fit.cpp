// fitExponentialWarmUp: the simulator's warm-up curve final + (start − final)·e^{−t/T} back
// from a temperature channel made from it (noise-free: exactly; with white noise of a known
// sd: within several standard errors; flat: its mean).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "processing/base/portable_random.hpp"
#include "processing/motion/warm_up_fit.hpp"

using namespace gyrod::processing;

namespace {

struct Channel {
  std::vector<double> secs, temp;
};

Channel warmUp(double start, double final_c, double tau, double duration, double rate, double noise_sd,
               std::uint64_t seed) {
  Channel c;
  NormalGenerator noise(seed);
  const auto n = static_cast<std::size_t>(duration * rate);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    c.secs.push_back(t);
    c.temp.push_back(final_c + (start - final_c) * std::exp(-t / tau) + noise_sd * noise.next());
  }
  return c;
}

TEST(ExponentialWarmUpFit, RecoversANoiseFreeCurve) {
  const Channel c = warmUp(24.0, 34.0, 400.0, 1800.0, 1.0, 0.0, 1);
  const TemperatureModel m = fitExponentialWarmUp(c.secs, c.temp);
  EXPECT_NEAR(m.time_constant_s, 400.0, 400.0 * 1e-5);
  EXPECT_NEAR(m.start_c, 24.0, 1e-4);
  EXPECT_NEAR(m.final_c, 34.0, 1e-4);
  // The differences of a smooth curve are its slope, not noise: at most 10 °C/400 s · 1 s / √2.
  EXPECT_LT(m.noise_std_c, 10.0 / 400.0 / std::sqrt(2.0));
}

TEST(ExponentialWarmUpFit, WithWhiteNoiseWithinItsErrors) {
  // 3600 samples with sd 0.05 °C: the fitted levels' standard errors are a few mK and T's
  // about 1 %; the difference-based sd's is ~1.5 %. Tolerances ≥ 5 standard errors.
  for (std::uint64_t seed : {2u, 3u, 4u}) {
    const Channel c = warmUp(21.0, 29.5, 600.0, 3600.0, 1.0, 0.05, seed);
    const TemperatureModel m = fitExponentialWarmUp(c.secs, c.temp);
    EXPECT_NEAR(m.time_constant_s, 600.0, 0.05 * 600.0) << "seed " << seed;
    EXPECT_NEAR(m.start_c, 21.0, 0.05) << "seed " << seed;
    EXPECT_NEAR(m.final_c, 29.5, 0.05) << "seed " << seed;
    EXPECT_NEAR(m.noise_std_c, 0.05, 0.1 * 0.05) << "seed " << seed;
  }
}

TEST(ExponentialWarmUpFit, AFlatChannelIsItsMean) {
  const std::vector<double> secs{0.0, 1.0, 2.0, 3.0}, temp(4, 25.5);
  const TemperatureModel m = fitExponentialWarmUp(secs, temp);
  EXPECT_DOUBLE_EQ(m.start_c, 25.5);
  EXPECT_DOUBLE_EQ(m.final_c, 25.5);
  EXPECT_DOUBLE_EQ(m.noise_std_c, 0.0);
}

TEST(ExponentialWarmUpFit, BadInputIsRejected) {
  const std::vector<double> one{0.0}, two{0.0, 1.0}, three{0.0, 1.0, 2.0};
  EXPECT_THROW(fitExponentialWarmUp(one, one), std::invalid_argument);
  EXPECT_THROW(fitExponentialWarmUp(two, three), std::invalid_argument);
  const std::vector<double> bad{20.0, std::numeric_limits<double>::quiet_NaN()};
  EXPECT_THROW(fitExponentialWarmUp(two, bad), std::invalid_argument);
}

}  // namespace
