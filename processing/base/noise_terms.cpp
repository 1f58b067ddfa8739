#include "processing/base/noise_terms.hpp"

#include <cmath>
#include <stdexcept>

#include "processing/base/units.hpp"

namespace gyrod::processing {
namespace {

// Scale s with c = (s·value)² where value is in paper units; derived from Table 1 with
// every quantity converted to °, s:
//   Q: σ = √3·Q/τ, Q[°] = Q[µrad]·1e-6·180/π          → c = 3·Q[°]²,       p = −2
//   N: σ = N/√τ,   N[°/√s] = N[°/√h]/60               → c = N[°/√s]²,      p = −1
//   B: σ = 0.6643·B, B[°/s] = B[°/h]/3600              → c = (0.6643·B)²,   p =  0
//   K: σ = K·√(τ/3), K[°/s/√s] = K[°/h/√h]/(3600·60)   → c = K²/3,          p = +1
//   R: σ = R·τ/√2,  R[°/s²] = R[°/h²]/3600²            → c = R²/2,          p = +2
double coefficientScale(NoiseTerm t) {
  switch (t) {
    case NoiseTerm::Quantization: return std::sqrt(3.0) * units::microradToDeg(1.0);
    case NoiseTerm::AngleRandomWalk: return 1.0 / units::kSqrtSecondsPerSqrtHour;
    case NoiseTerm::BiasInstability: return kBiasInstabilityFactor / units::kSecondsPerHour;
    case NoiseTerm::RateRandomWalk:
      return 1.0 / (units::kSecondsPerHour * units::kSqrtSecondsPerSqrtHour) / std::sqrt(3.0);
    case NoiseTerm::RateRamp: return 1.0 / (units::kSecondsPerHour * units::kSecondsPerHour) / std::sqrt(2.0);
  }
  throw std::invalid_argument("unknown noise term");
}

}  // namespace

double NoiseTerms::get(NoiseTerm t) const {
  switch (t) {
    case NoiseTerm::Quantization: return quantization_urad;
    case NoiseTerm::AngleRandomWalk: return arw_deg_per_sqrt_h;
    case NoiseTerm::BiasInstability: return bias_instability_deg_per_h;
    case NoiseTerm::RateRandomWalk: return rrw_deg_per_h_sqrt_h;
    case NoiseTerm::RateRamp: return rate_ramp_deg_per_h2;
  }
  throw std::invalid_argument("unknown noise term");
}

void NoiseTerms::set(NoiseTerm t, double value) {
  switch (t) {
    case NoiseTerm::Quantization: quantization_urad = value; return;
    case NoiseTerm::AngleRandomWalk: arw_deg_per_sqrt_h = value; return;
    case NoiseTerm::BiasInstability: bias_instability_deg_per_h = value; return;
    case NoiseTerm::RateRandomWalk: rrw_deg_per_h_sqrt_h = value; return;
    case NoiseTerm::RateRamp: rate_ramp_deg_per_h2 = value; return;
  }
  throw std::invalid_argument("unknown noise term");
}

std::string_view noiseTermKey(NoiseTerm t) {
  switch (t) {
    case NoiseTerm::Quantization: return "quantization_urad";
    case NoiseTerm::AngleRandomWalk: return "arw_deg_per_sqrt_h";
    case NoiseTerm::BiasInstability: return "bias_instability_deg_per_h";
    case NoiseTerm::RateRandomWalk: return "rrw_deg_per_h_sqrt_h";
    case NoiseTerm::RateRamp: return "rate_ramp_deg_per_h2";
  }
  throw std::invalid_argument("unknown noise term");
}

std::string_view noiseTermLabel(NoiseTerm t) {
  switch (t) {
    case NoiseTerm::Quantization: return "quantization Q [urad]";
    case NoiseTerm::AngleRandomWalk: return "angle random walk N [deg/sqrt(h)]";
    case NoiseTerm::BiasInstability: return "bias instability B [deg/h]";
    case NoiseTerm::RateRandomWalk: return "rate random walk K [deg/h^1.5]";
    case NoiseTerm::RateRamp: return "rate ramp R [deg/h^2]";
  }
  throw std::invalid_argument("unknown noise term");
}

double noiseTermSlope(NoiseTerm t) { return 0.5 * noiseTermVariancePower(t); }

int noiseTermVariancePower(NoiseTerm t) {
  switch (t) {
    case NoiseTerm::Quantization: return -2;
    case NoiseTerm::AngleRandomWalk: return -1;
    case NoiseTerm::BiasInstability: return 0;
    case NoiseTerm::RateRandomWalk: return 1;
    case NoiseTerm::RateRamp: return 2;
  }
  throw std::invalid_argument("unknown noise term");
}

double allanVarianceCoefficient(NoiseTerm t, double value_paper_units) {
  const double s = coefficientScale(t) * value_paper_units;
  return s * s;
}

double noiseTermFromCoefficient(NoiseTerm t, double coefficient) {
  if (coefficient <= 0.0) return 0.0;
  return std::sqrt(coefficient) / coefficientScale(t);
}

double allanVarianceOfTerm(NoiseTerm t, double value_paper_units, double tau_s) {
  return allanVarianceCoefficient(t, value_paper_units) * std::pow(tau_s, noiseTermVariancePower(t));
}

double allanVarianceOfTerms(const NoiseTerms& terms, double tau_s) {
  double sum = 0.0;
  for (NoiseTerm t : kAllNoiseTerms) sum += allanVarianceOfTerm(t, terms.get(t), tau_s);
  return sum;
}

}  // namespace gyrod::processing
