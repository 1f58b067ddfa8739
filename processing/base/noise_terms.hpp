#pragma once
// The five IEEE Std 952-1997 (Annex C) noise terms of a gyro and their Allan
// variance. Each term's formula is written once here and used by the fit, the
// simulator and the reports. Paper units (Xiong et al., Table 1):
//   Q  quantization noise   σ(τ) = √3·Q/τ      µrad
//   N  angle random walk    σ(τ) = N/√τ        °/√h
//   B  bias instability     σ(τ) = 0.6643·B    °/h   (flat part, the minimum)
//   K  rate random walk     σ(τ) = K·√(τ/3)    °/h^1.5
//   R  rate ramp            σ(τ) = R·τ/√2      °/h²
// σ is in °/s and τ in s after conversion.
#include <array>
#include <string_view>

namespace gyrod::processing {

enum class NoiseTerm { Quantization = 0, AngleRandomWalk, BiasInstability, RateRandomWalk, RateRamp };
inline constexpr std::size_t kNoiseTermCount = 5;
inline constexpr std::array<NoiseTerm, kNoiseTermCount> kAllNoiseTerms = {
    NoiseTerm::Quantization, NoiseTerm::AngleRandomWalk, NoiseTerm::BiasInstability, NoiseTerm::RateRandomWalk,
    NoiseTerm::RateRamp};

// The flat level of the Allan deviation of flicker (1/f) rate noise, σ = √(2 ln 2 / π)·B.
inline constexpr double kBiasInstabilityFactor = 0.6643;

// Values in the paper's units. Field names match the JSON of `gyroctl analyze`.
struct NoiseTerms {
  double quantization_urad = 0.0;
  double arw_deg_per_sqrt_h = 0.0;
  double bias_instability_deg_per_h = 0.0;
  double rrw_deg_per_h_sqrt_h = 0.0;
  double rate_ramp_deg_per_h2 = 0.0;

  double get(NoiseTerm t) const;
  void set(NoiseTerm t, double value);
};

// JSON / TOML key of a term, e.g. "arw_deg_per_sqrt_h".
std::string_view noiseTermKey(NoiseTerm t);
// Human label, e.g. "angle random walk N [°/√h]".
std::string_view noiseTermLabel(NoiseTerm t);
// Log-log slope of σ(τ) for the term: −1, −1/2, 0, +1/2, +1.
double noiseTermSlope(NoiseTerm t);
// Power p of τ in the term's Allan *variance*: σ²(τ) = c·τ^p (p = −2, −1, 0, 1, 2).
int noiseTermVariancePower(NoiseTerm t);

// The coefficient c with σ²(τ) = c·τ^p (σ in °/s, τ in s) for a term of the given value
// in paper units, and the inverse. allanVarianceCoefficient(t, v) is proportional to v².
double allanVarianceCoefficient(NoiseTerm t, double value_paper_units);
double noiseTermFromCoefficient(NoiseTerm t, double coefficient);

// σ²(τ) [(°/s)²] of one term, and of all five together (terms are independent, so
// their Allan variances add).
double allanVarianceOfTerm(NoiseTerm t, double value_paper_units, double tau_s);
double allanVarianceOfTerms(const NoiseTerms& terms, double tau_s);

}  // namespace gyrod::processing
