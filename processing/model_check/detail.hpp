#pragma once
// Internal parts of the model check (processing/model_check/*.cpp), shared between its
// files and the tests. Not a stable interface.
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "processing/base/noise_terms.hpp"
#include "processing/paper/ar_model.hpp"
#include "processing/simulation/narrowband_line.hpp"

namespace gyrod::processing::model_check_detail {

// ---- null distributions -------------------------------------------------------------
// A statistic's null from the replicas and the threshold it must pass to fire:
// max(largest replica, the (1 − α) quantile of a model of the null fitted to the replicas'
// median and spread). One-sided statistics here are maxima (of spectral ratios, robust z,
// Haar differences, χ² gains), so the model is a Gumbel distribution: scale β =
// (q90 − q50)/1.8834, threshold q50 + β·(−ln(−ln(1 − α)) − 0.3665). Two-sided (a signed,
// linear, hence Gaussian statistic): spread σ = (q84 − q16)/2, and |value − median| must
// exceed σ·Φ⁻¹(1 − α/2). Both from quantiles, so one odd replica cannot move them much.
struct NullSummary {
  double median = 0.0;
  double spread = 0.0;     // β (one-sided) or σ (two-sided)
  double largest = 0.0;    // largest replica value (of |v − median| when two-sided)
  double threshold = 0.0;  // on the value (one-sided) or on |value − median| (two-sided)
  bool two_sided = false;
  bool fires(double value) const;
  double excess(double value) const;  // (value − median)/spread, |·| when two-sided
};
NullSummary summarizeNull(std::vector<double> values, double alpha, bool two_sided);

// Quantile of sorted data by linear interpolation (q in [0, 1]).
double sortedQuantile(const std::vector<double>& sorted, double q);

// ---- series helpers ---------------------------------------------------------------------
// Means of consecutive blocks of `length` samples (a trailing partial block is dropped).
std::vector<double> blockMeans(std::span<const double> x, std::size_t length);
// x minus its least-squares line in the index (in place).
void removeLineInPlace(std::span<double> x);

// ---- spectrum ------------------------------------------------------------------------
// FFT length used for n samples: the smallest multiple of 4 ≥ n with no prime factor above 5.
std::size_t fftLength(std::size_t n);
// Hann-windowed periodogram |X_k|², k = 0..nfft/2, nfft = fftLength(n) (zero padded).
struct Periodogram {
  std::vector<double> power;
  std::size_t nfft = 0;
  double window_power = 0.0;  // Σ w_i²
};
Periodogram hannPeriodogram(std::span<const double> x);
// Local background level of a periodogram: medians over blocks whose width grows with k
// (k/8, 16..128 bins), divided by ln 2 (the median of an exponential of mean 1), and
// interpolated in log between block centres.
std::vector<double> spectralBackground(const std::vector<double>& power);
// What both backgrounds are made of: medians of consecutive blocks of bins from bin 1 (the
// block at bin k `width_at(k)` wide; a last block shorter than `shortest_last` joins the one
// before), ÷ ln 2, log-linear between block centres.
std::vector<double> blockMedianLevels(const std::vector<double>& power,
                                      const std::function<std::size_t(std::size_t)>& width_at,
                                      std::size_t shortest_last);
// Largest power/background over bins [k_lo, k_hi], and where.
struct SpectralPeak {
  double ratio = 0.0;
  std::size_t bin = 0;
};
SpectralPeak largestSpectralPeak(const std::vector<double>& power, const std::vector<double>& background,
                                 std::size_t k_lo, std::size_t k_hi);
// One-sided PSD [(unit)²/Hz] averaged over the log-spaced bands [edges_j, edges_{j+1});
// band_max (optional) gets the largest single-bin PSD of each band (where a line shows).
std::vector<double> bandAveragedPsd(const Periodogram& p, double rate_hz, std::span<const double> edges_hz,
                                    std::vector<double>* band_max = nullptr);

// ---- steps ---------------------------------------------------------------------------
// Haar differences D_W(t) = mean(y[t, t+W)) − mean(y[t−W, t)) for t = W..n−W.
struct HaarScan {
  double max_abs = 0.0;
  std::size_t argmax = 0;  // t of the largest |D|
  double value_at_max = 0.0;
  double sum_squares = 0.0;
  std::size_t count = 0;
  double median_abs = 0.0;  // median of |D| over the positions
};
HaarScan haarScan(std::span<const double> y, std::size_t w);

// ---- Gauss–Markov in the Allan curve ---------------------------------------------------
// Weighted NNLS of σ²(τ) by the five terms, and by the five terms plus one Gauss–Markov
// column g_T(τ) = gaussMarkovAllanVariance(τ, T, 1) (coefficient σ²) for each T of a grid.
// Weights: σ̂² has variance 2·ref²/edf; ref = the measured σ² in a first pass, then the
// better fit's model value (at least 1/10 of the measured one), as noise_fit does.
struct GaussMarkovCurveFit {
  double chi2_base = 0.0;     // weighted residual of the five-term fit
  double chi2_with_gm = 0.0;  // of the best five-terms-plus-GM fit
  double improvement = 0.0;   // chi2_base − chi2_with_gm
  double tau_s = 0.0;         // best T
  double sigma_dps = 0.0;     // its σ
  NoiseTerms terms_with_gm;   // the five terms of that fit
};
GaussMarkovCurveFit fitGaussMarkovToAllan(std::span<const double> tau_s, std::span<const double> variance,
                                          std::span<const double> edf, std::span<const double> t_grid);

// ---- AR / Kalman innovations --------------------------------------------------------------
// Levinson–Durbin on a given autocovariance γ(0..p): φ and σa² of order p. Returns false
// when γ is not positive definite up to p (a reflection coefficient |κ| ≥ 1).
bool levinsonFromAutocovariance(std::span<const double> gamma, std::size_t order, std::vector<double>& phi,
                                double& noise_var);

// One-step innovations of the Kalman filter of z = AR(p) state [+ a Gauss–Markov state g,
// g_k = ρ·g_{k−1} + w, var(w) = q_g], measured without further noise. When `robust`, an
// innovation beyond 5·√S is a gross error: the update is skipped (the prediction stands
// in for the sample) and the sample is left out of the statistics.
struct InnovationStats {
  double variance = 0.0;            // mean square innovation over the samples used
  std::vector<double> innovations;  // samples used, after a burn-in of 100
  std::size_t rejected = 0;
  std::vector<std::size_t> rejected_samples;  // indices into z of the rejected samples
};
// `lines`: narrowband lines (simulation/narrowband_line.hpp), each two more states
// [y_k, y_{k−1}] with y_k = a1·y_{k−1} + a2·y_{k−2} + e_k, measured with the rest.
inline constexpr std::size_t kMaxInnovationLines = 6;
InnovationStats kalmanInnovations(std::span<const double> z, std::span<const double> phi, double ar_noise_var,
                                  double gm_decay, double gm_noise_var, bool robust,
                                  std::span<const NarrowbandLineRecursion> lines = {});

}  // namespace gyrod::processing::model_check_detail
