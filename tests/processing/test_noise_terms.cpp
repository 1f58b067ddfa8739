// Noise-term conversions against the definitions of IEEE 952 Table 1 read at the
// conventional τ where σ equals the term itself (in the term's own unit).
#include <gtest/gtest.h>

#include <cmath>

#include "processing/base/noise_terms.hpp"

using namespace gyrod::processing;

namespace {
double sigmaDps(NoiseTerm t, double value, double tau_s) { return std::sqrt(allanVarianceOfTerm(t, value, tau_s)); }
}  // namespace

TEST(NoiseTerms, AngleRandomWalkEqualsSigmaAtOneHourInDegPerHour) {
  // σ(τ) = N/√τ: at τ = 1 h, σ [°/h] = N [°/√h].
  EXPECT_NEAR(sigmaDps(NoiseTerm::AngleRandomWalk, 0.95164, 3600.0) * 3600.0, 0.95164, 1e-12);
}

TEST(NoiseTerms, BiasInstabilityIsFlatAtFactorTimesB) {
  for (double tau : {0.1, 10.0, 1000.0})
    EXPECT_NEAR(sigmaDps(NoiseTerm::BiasInstability, 0.60565, tau) * 3600.0, 0.6643 * 0.60565, 1e-12);
}

TEST(NoiseTerms, RateRandomWalkEqualsSigmaAtThreeHours) {
  // σ(τ) = K·√(τ/3): at τ = 3 h, σ [°/h] = K [°/h^1.5].
  EXPECT_NEAR(sigmaDps(NoiseTerm::RateRandomWalk, 0.07759, 3.0 * 3600.0) * 3600.0, 0.07759, 1e-12);
}

TEST(NoiseTerms, RateRampEqualsSigmaAtRootTwoHours) {
  // σ(τ) = R·τ/√2: at τ = √2 h, σ [°/h] = R [°/h²]·1 h.
  EXPECT_NEAR(sigmaDps(NoiseTerm::RateRamp, 0.43223, std::sqrt(2.0) * 3600.0) * 3600.0, 0.43223, 1e-12);
}

TEST(NoiseTerms, QuantizationEqualsSigmaAtRootThreeSeconds) {
  // σ(τ) = √3·Q/τ: at τ = √3 s, σ [rad/s] = Q [rad].
  const double sigma_rad_per_s = sigmaDps(NoiseTerm::Quantization, 0.1663, std::sqrt(3.0)) * M_PI / 180.0;
  EXPECT_NEAR(sigma_rad_per_s * 1e6, 0.1663, 1e-12);
}

TEST(NoiseTerms, CoefficientRoundTrips) {
  for (NoiseTerm t : kAllNoiseTerms) {
    const double c = allanVarianceCoefficient(t, 0.37);
    EXPECT_NEAR(noiseTermFromCoefficient(t, c), 0.37, 1e-12) << noiseTermKey(t);
  }
  EXPECT_EQ(noiseTermFromCoefficient(NoiseTerm::RateRamp, 0.0), 0.0);
}

TEST(NoiseTerms, TermsAddInVariance) {
  NoiseTerms terms;
  terms.arw_deg_per_sqrt_h = 1.0;
  terms.bias_instability_deg_per_h = 2.0;
  const double tau = 5.0;
  EXPECT_NEAR(allanVarianceOfTerms(terms, tau),
              allanVarianceOfTerm(NoiseTerm::AngleRandomWalk, 1.0, tau) +
                  allanVarianceOfTerm(NoiseTerm::BiasInstability, 2.0, tau),
              1e-20);
}
