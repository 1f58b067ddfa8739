#pragma once
// The model check's 95 % intervals of the named effects' parameters (docs/model-check.md,
// "Intervals"). The noise under an effect is coloured (flicker, random walk, a DLPF), so
// white-noise standard errors would be too narrow; instead the extended model's replicas,
// which carry every named effect at its fitted size on top of the fitted noise, are measured
// by the same estimators as the record: a parametric bootstrap. The linear parameters (step
// sizes, the sinusoid's sine and cosine parts, the temperature coefficient) are refitted
// jointly by least squares on each replica; the Gauss–Markov term by the Allan fit. The
// interval is the estimate ± 1.96 × the replicas' robust spread (log scale for T and σ; T's
// widened by one step of its fitting grid, which the replicas cannot show); the sinusoid's
// amplitude from the Rice distribution of √(a² + b²) with the parts' pooled replica spread.
// Outliers: an exact Poisson interval of the count, and the median excursion's normal one.
// A narrowband line: its centre, width and rms refitted on each replica by the same Whittle
// fit (narrowband.cpp); normal interval for the centre, log scale for width and rms.
#include <cstddef>
#include <span>
#include <vector>

#include "processing/model_check/model_check.hpp"
#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing {

// estimate ± 1.96·s, s = half the 15.9–84.1 % spread of the replicas' estimates (robust to a
// few wild ones); not stated with fewer than 8 finite values.
ParameterInterval bootstrapInterval(double estimate, std::span<const double> replica_estimates);
// The same on the log scale (for positive parameters); replicas ≤ 0 count as far below.
ParameterInterval logBootstrapInterval(double estimate, std::span<const double> replica_estimates);
// Exact (Garwood) 95 % interval of a Poisson mean from one count.
ParameterInterval poissonInterval(std::size_t count);
// P(R ≤ r) for R Rice-distributed with noncentrality ν and unit scale: the length of a 2-D
// normal vector of unit variance per coordinate whose mean is ν from the origin.
double riceCdf(double r, double nu);
// A sinusoid's amplitude A = √(a² + b²) from its fitted amplitude and the replicas' fitted
// sine and cosine parts (a, b): (â, b̂) ~ N((a, b), s²·I), s² pooled from both parts' replica
// variances (2R − 2 degrees of freedom, s widened by t₀.₉₇₅/z₀.₉₇₅ for being estimated), so
// Â/s is Rice(A/s); the interval is every A whose Rice distribution puts Â/s inside its
// central 95 % (Neyman's construction: exact at any SNR, lower limit 0 when Â is
// compatible with no line). Not stated with fewer than 8 finite replica pairs.
ParameterInterval sinusoidAmplitudeInterval(double amplitude, std::span<const double> replica_a,
                                            std::span<const double> replica_b);

}  // namespace gyrod::processing

namespace gyrod::processing::model_check_detail {

// The linear part: the regressors of the named deterministic effects (and a line, which the
// detrending takes out), their joint least squares on a replica by index (thread-safe for
// distinct indices), then the intervals written into the effects.
class EffectIntervals {
 public:
  EffectIntervals(const Removal& removal, const Context& c, const std::vector<double>& temperature_regressor,
                  std::size_t replicas);
  bool empty() const { return columns_ == 0 && removal_.lines.empty(); }
  void measureReplica(std::size_t index, std::span<const double> x);
  // Replicas' Allan curves → the Gauss–Markov fit's T and σ on each.
  void measureGaussMarkov(const std::vector<SeriesStats>& reps, const Context& c);
  // Intervals into out.effects; `cleaned` (the record with the effects removed) gives the
  // noise under the outliers.
  void state(AxisModelCheck& out, std::span<const double> cleaned) const;

 private:
  std::vector<double> solve(std::span<const double> x) const;
  const Removal& removal_;
  std::size_t n_ = 0, columns_ = 0, first_effect_column_ = 2;
  std::vector<std::vector<double>> regressors_;  // column-major, n each
  std::vector<double> gram_inverse_;             // columns_ × columns_
  std::vector<std::vector<double>> estimates_;   // per replica, the effect columns' estimates
  // Narrowband lines, refitted on each replica: per replica, centre, width and rms per line.
  void measureLines(std::size_t index, std::span<const double> x);
  const Context& context_;
  std::vector<std::vector<double>> line_estimates_;
  std::vector<double> gm_tau_, gm_sigma_;
  double gm_tau_grid_step_ = 0.0;  // the T grid's step, log scale
};

}  // namespace gyrod::processing::model_check_detail
