// The model check's line detector: peaks in the spectrum, each fitted and removed — a fixed
// sinusoid subtracted, a narrowband line (narrowband.cpp) shrunk out.
#include <cmath>
#include <numbers>

#include "processing/base/golden_section.hpp"
#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

// Lines named per axis (fixed sinusoids and narrowband lines together).
constexpr std::size_t kMaxLines = 6;
constexpr double kSameLineBins = 3.0;  // peaks closer than this (periodogram bins) are one line

// The least-squares sinusoid at the frequency within ±1 bin of `bin` of largest amplitude.
SinusoidFit fitLineNearBin(std::span<const double> x, double rate, std::size_t bin, double df) {
  const double a = (static_cast<double>(bin) - 1.0) * df, b = (static_cast<double>(bin) + 1.0) * df;
  const GoldenSectionBracket found =
      goldenSectionMinimum(a, b, {40, 1e-6 * df}, [&](double f) { return -fitSinusoidAt(x, rate, f).amp_dps; });
  return fitSinusoidAt(x, rate, found.midpoint());
}

// The effect already named within a few bins of `freq_hz`, if any (the last such).
DetectedEffect* sameLine(std::vector<DetectedEffect>& effects, double freq_hz, double df) {
  DetectedEffect* same_line = nullptr;
  for (DetectedEffect& prev : effects)
    if (prev.effect == ModelEffect::Sinusoid && std::fabs(prev.freq_hz - freq_hz) <= kSameLineBins * df)
      same_line = &prev;
  return same_line;
}

// A line wider than a bin: named as a narrowband line, shrunk out of xc.
void nameNarrowbandLine(std::vector<double>& xc, const NarrowbandFit& fit, const Context& c, double stat,
                        const NullSummary& null, std::size_t replicas, Removal& removal, AxisModelCheck& out) {
  const NarrowbandLine line{fit.centre_hz, fit.width_hz, fit.rms_dps};
  shrinkNarrowbandLine(xc, line, fit.background_psd, c.rate);
  removal.lines.push_back(line);
  DetectedEffect e;
  e.effect = ModelEffect::NarrowbandLine;
  e.centre_hz = fit.centre_hz;
  e.width_hz = fit.width_hz;
  e.rms_dps = fit.rms_dps;
  e.evidence = nullEvidence(stat, null, replicas);
  e.evidence.freq_hz = fit.centre_hz;
  out.effects.push_back(e);
}

}  // namespace

bool checkSinusoids(std::vector<double>& xc, const Context& c, const NullSummary& null, const NullSummary& scan_null,
                    std::size_t replicas, Removal& removal, AxisModelCheck& out) {
  const double rate = c.rate;
  bool found = false;
  for (std::size_t s = 0; s < kMaxLines; ++s) {
    const Periodogram p = hannPeriodogram(xc);
    const SpectralPeak peak = largestSpectralPeak(p.power, spectralBackground(p.power), c.k_lo, c.k_hi);
    const double stat = std::log(peak.ratio);
    const std::vector<double> wide_bg = blockMedianBackground(p.power, c.line_background_block);
    LineScan scan = scanForLines(p.power, wide_bg, c.k_lo, c.k_hi, c.line_scales);
    const double df = rate / static_cast<double>(p.nfft);
    const HalfLineScan half = scanHalvesForLines(xc, c);
    const bool half_wins = half.statistic > scan.statistic;
    if (half_wins) scan.statistic = half.statistic;
    if (s == 0) {
      out.statistics.push_back(makeStatistic("spectral_peak_log_ratio", stat, null));
      out.statistics.push_back(makeStatistic("narrowband_scan", scan.statistic, scan_null));
    }
    const bool peak_fires = null.fires(stat), scan_fires = !c.line_scales.empty() && scan_null.fires(scan.statistic);
    if (!peak_fires && !scan_fires) break;
    // The line's shape decides its kind: fitted as a resonance where it fired, resolved wider
    // than a bin it is a narrowband line.
    {
      NarrowbandFit fit;
      if (!peak_fires && half_wins) {
        // Fitted on the half that holds it: diluted over the whole record, a line whose power
        // changes is a bump the fit would merge with its neighbours.
        const LineScanSegment& seg = c.line_halves[half.half];
        const Periodogram ph = hannPeriodogram(std::span<const double>(xc).subspan(seg.offset, seg.length));
        const double dfh = rate / static_cast<double>(ph.nfft);
        fit = fitNarrowbandLine(onesidedPsd(ph, rate),
                                onesidedPsd(ph, blockMedianBackground(ph.power, seg.background_block), rate), dfh, rate,
                                static_cast<std::size_t>(std::lround(half.centre_hz / dfh)),
                                static_cast<std::size_t>(std::lround(half.width_hz / dfh)), seg.k_lo, seg.k_hi);
      } else {
        const std::size_t centre = peak_fires ? peak.bin : scan.centre_bin;
        const std::size_t width = peak_fires ? 4 : scan.width_bins;
        fit = fitNarrowbandLine(onesidedPsd(p, rate), onesidedPsd(p, wide_bg, rate), df, rate, centre, width, c.k_lo,
                                c.k_hi);
      }
      // Broader than any line: no catalogue entry (the Allan band names it unexplained).
      if (fit.fitted && fit.broadband) break;
      if (fit.fitted && fit.resolved) {
        nameNarrowbandLine(xc, fit, c, scan_fires ? scan.statistic : stat, scan_fires ? scan_null : null, replicas,
                           removal, out);
        found = true;
        continue;
      }
      if (!peak_fires) break;  // the scan's band is a fixed sinusoid too weak for the peak test
    }
    const SinusoidFit fit = fitLineNearBin(xc, rate, peak.bin, df);
    const double w = 2.0 * std::numbers::pi * fit.freq_hz / rate;
    for (std::size_t i = 0; i < xc.size(); ++i)
      xc[i] -= fit.amp_dps * std::sin(w * static_cast<double>(i) + fit.phase_rad);
    removal.sinusoids.push_back(fit);
    // A second peak within a few bins of one already named is the same line: a fixed
    // sinusoid did not take it out because its amplitude or phase wanders over the record
    // (or gaps in the record shifted its phase). Both components stay in the extended model;
    // the report names one line, its frequency power-weighted and its amplitude the rms sum.
    if (DetectedEffect* same_line = sameLine(out.effects, fit.freq_hz, df)) {
      const double p0 = same_line->amp_dps * same_line->amp_dps, p1 = fit.amp_dps * fit.amp_dps;
      same_line->evidence.further_components.push_back({fit.freq_hz, fit.amp_dps, peak.ratio});
      same_line->freq_hz = (p0 * same_line->freq_hz + p1 * fit.freq_hz) / (p0 + p1);
      same_line->amp_dps = std::sqrt(p0 + p1);
      continue;
    }
    DetectedEffect e;
    e.effect = ModelEffect::Sinusoid;
    e.freq_hz = fit.freq_hz;
    e.amp_dps = fit.amp_dps;
    e.phase_rad = fit.phase_rad;
    e.evidence = nullEvidence(stat, null, replicas);
    e.evidence.peak_ratio = peak.ratio;
    e.evidence.freq_hz = fit.freq_hz;
    out.effects.push_back(e);
    found = true;
  }
  return found;
}

}  // namespace gyrod::processing::model_check_detail
