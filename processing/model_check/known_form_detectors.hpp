#pragma once
// Detectors that KNOW the form of the effect they look for: the reference the blind model
// check (processing/model_check/model_check.hpp) is measured against in its detection curves
// (bench/model_check_curves.cpp, docs/model-check.md "Detection curves"). A blind method,
// which must find the effect's time, frequency or correlation time and must estimate the
// noise model from the same record, cannot do better than a test told them. Each statistic
// is a single number that grows with the effect; its threshold at a given false-alarm rate
// comes from the same statistic on clean records of the same noise model
// (calibratedThreshold), so that coloured noise (flicker, random walk) is accounted for
// exactly, whatever the statistic's textbook null under white noise.
//
// What each one knows, and in what sense it is the bound:
// - step: its sample (the GLR for a step at a KNOWN time, unknown height; in white noise the
//   optimum is the difference of the means before and after it; with slow noise, shorter
//   windows, so the largest standardised difference over dyadic windows is taken);
// - sinusoid: its frequency (the coherent detector: least-squares amplitude at that
//   frequency, unknown phase; χ²(2) in white noise);
// - temperature: the temperature series (the regression t-statistic of the rate's block
//   means on it, both with their lines removed);
// - Gauss–Markov: its correlation time and the base noise spectrum (the locally most
//   powerful score test for a component of known spectral shape added to a known spectrum).
// Pure: no I/O.
#include <cstddef>
#include <span>
#include <vector>

namespace gyrod::processing {

// Step at a known sample. Block means of `block` samples (no line removed: a line fitted
// through a step takes part of it, and the difference ignores the constant); for each dyadic
// window W = 1, 2, 4, … blocks that fits on both sides of the block boundary nearest the
// step: mean of the W blocks after − mean of the W before (signed). Entry j is W = 2^j.
// Throws std::invalid_argument when the step sample is not inside the series or fewer than
// 4 blocks fit.
std::vector<double> knownStepDifferences(std::span<const double> x, std::size_t step_sample, std::size_t block);
// The step statistic: max over j of |d_j| / sd_j, sd_j the standard deviation of entry j on
// clean records of the same noise model (the detector knows it; a series cannot normalise
// itself here, because the step inflates every difference that straddles it). Entries
// without a positive sd are skipped.
double knownStepStatistic(std::span<const double> differences, std::span<const double> clean_sd);

// Sinusoid of known frequency: n·A²/(2·s²) with A the least-squares amplitude at freq_hz
// (t = i/rate) and s² the variance of x about its line: χ²(2) for white Gaussian noise, so
// its 1 % point there is 2·ln 100. Throws std::invalid_argument for fewer than 4 samples
// or a frequency outside (0, rate/2).
double knownSinusoidStatistic(std::span<const double> x, double rate_hz, double freq_hz);

// Temperature response with the temperature known: the OLS t-statistic |k̂|/se(k̂) of the
// block means of x on the block means of temperature (both with their least-squares line
// removed), se from the residual variance of the blocks. Student t(m − 3) when the block
// means are white. Throws std::invalid_argument for a length mismatch, fewer than 8 blocks
// or a temperature that does not move about its line.
double knownTemperatureStatistic(std::span<const double> x, std::span<const double> temperature_c, std::size_t block);

// Score test for a spectral component of known shape g_k added to a known expected
// periodogram b_k (same bins): Σ w_k (P_k/b_k − 1) / √(Σ w_k²) with w_k = g_k/b_k, the
// locally most powerful test of P_k ~ (b_k + ε·g_k)·Exp(1). Standard normal for
// independent exponential bins of mean b_k. Bins where b_k ≤ 0 are skipped. Throws
// std::invalid_argument for sizes that differ or no usable bin.
double spectralScoreStatistic(std::span<const double> power, std::span<const double> base_power,
                              std::span<const double> shape);

// Spectrum of a first-order Gauss–Markov process of correlation time T sampled at `rate`
// (an AR(1) of ρ = e^{−1/(rate·T)}), up to a constant: (1 − ρ²)/(1 − 2ρ·cos(2π k/nfft) + ρ²)
// for the bins k = 0..nfft/2 of an nfft-point transform.
std::vector<double> gaussMarkovSpectralShape(double correlation_time_s, double rate_hz, std::size_t nfft);

// The (1 − false_alarm) empirical quantile of a statistic on clean records (linear
// interpolation between order statistics). Throws std::invalid_argument for an empty set
// or a false-alarm rate outside (0, 1).
double calibratedThreshold(std::vector<double> clean_values, double false_alarm);

}  // namespace gyrod::processing
