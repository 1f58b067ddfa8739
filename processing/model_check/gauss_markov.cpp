// The model check's Gauss–Markov detector: a bump in the Allan curve of what is left once the
// deterministic effects are removed, that a first-order Gauss–Markov term fits.
#include <algorithm>

#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {
// The Gauss–Markov statistic's share of the per-axis false-alarm budget: 10 × the nominal α
// of a statistic (1e-3 at the default 1e-4), as the step statistic's (steps.cpp).
// The square root of the χ² gain has a null tail the Gumbel model holds to (the raw gain's
// did not: docs/model-check.md), so the extra budget buys power, measured on the detection
// curves, at a clean-data rate that stays within the 1 % per axis of issue 13.
constexpr double kGaussMarkovAlphaFactor = 10.0;
// The guard on the joint-fit null, as a multiple of the nominal α: without a deterministic
// effect, the statistic must also exceed the five-term fit's null (the base replicas) at
// 100 α (1e-2 at the default 1e-4). The joint fit trades the flicker for the Gauss–Markov
// column (and a random walk or ramp) on clean records as on records with a process, so its
// replicas can carry less slow noise than the record: alone, its null named a process on 5 of
// 900 clean axes without a DLPF, 5 × its 10 α (docs/model-check.md "The Gauss–Markov null",
// measured at 4c35414).
constexpr double kGaussMarkovGuardFactor = 100.0;
// The replica round of the Gauss–Markov null (rounds 1 and 3 are the base and extended
// models', 4 + look the step looks').
constexpr std::uint64_t kGaussMarkovRound = 2;
}  // namespace

GaussMarkovFound checkGaussMarkov(std::span<const double> xc, const Context& c, bool deterministic_found,
                                  const std::vector<AllanPoint>& curve, const std::vector<SeriesStats>& base_reps,
                                  const ModelCheckOptions& o, AxisModelCheck& out) {
  GaussMarkovFound gm;
  const std::vector<AllanPoint> clean_curve = deterministic_found ? allanDeviationTable(xc, c.tau0, c.ms) : curve;
  gm.clean_fit = deterministic_found ? fitNoiseTerms(clean_curve) : out.base_fit;
  std::vector<double> clean_var;
  clean_var.reserve(clean_curve.size());
  for (const AllanPoint& p : clean_curve) clean_var.push_back(p.oadev * p.oadev);
  gm.fit = fitGaussMarkovToAllan(c.taus, clean_var, c.edf, c.t_grid);
  // The null: replicas of the five terms fitted jointly with the Gauss–Markov column, not of
  // the five-term fit. Without a Gauss–Markov process the two agree (its σ fits to ~0); with
  // one, the five-term fit absorbs it into a larger flicker and random walk, whose replicas
  // (their flicker a bank of Gauss–Markov processes, docs/simulator.md) then show larger χ²
  // gains: the threshold grew with the effect. Through a DLPF the joint fit's terms are not
  // in the chain's units (its columns are plain power laws, and the Gauss–Markov column
  // takes up the roll-off: clean DLPF_CFG 6 data then named a process), so there the null
  // stays the five-term fit's (the base replicas, or round 2's of the cleaned series).
  const double stat = gaussMarkovStatistic(gm.fit);
  const double alpha = o.false_alarm * kGaussMarkovAlphaFactor;
  // A statistic at or below the base replicas' median fires against neither null (a null's
  // threshold is above the largest of its replicas, which such a statistic would need to
  // exceed with all of them below the base median): the extra round is skipped then, about
  // one axis in two, so an hour keeps to its budget. With a deterministic effect named the
  // cleaned series' terms differ from the base fit's by what the effect took, which moves the
  // statistic's null far less than from its median to above its largest replica.
  const std::vector<double> base_stats = column(base_reps, &SeriesStats::gm_statistic);
  const bool above_base_median = stat > summarizeNull(base_stats, alpha, false).median;
  const bool joint = !c.chain.dlpf_cfg.has_value() && above_base_median;
  std::vector<SeriesStats> own_reps;
  if (joint || (deterministic_found && above_base_median)) {
    const SimulationModel model = pureModel(c.rate, joint ? gm.fit.terms_with_gm : gm.clean_fit.value);
    own_reps = runReplicas(model, statisticalUncertainty(gm.clean_fit), c, {}, o, kGaussMarkovRound, kStatGaussMarkov);
    out.replicas_simulated += o.replicas;
  }
  const std::vector<SeriesStats>& reps = own_reps.empty() ? base_reps : own_reps;
  NullSummary null = summarizeNull(column(reps, &SeriesStats::gm_statistic), alpha, false);
  // The guard (kGaussMarkovGuardFactor): where the joint null is used on an axis with nothing
  // deterministic named, the threshold is the larger of the joint null's (at 10 α) and the
  // base replicas' (the five-term null of the same series, at 100 α). With something named,
  // the base replicas are of the uncleaned series, not a null of this statistic: no guard
  // there (not measured, docs/model-check.md).
  if (joint && !deterministic_found)
    null.threshold =
        std::max(null.threshold, summarizeNull(base_stats, o.false_alarm * kGaussMarkovGuardFactor, false).threshold);
  out.statistics.push_back(makeStatistic("gauss_markov_sqrt_chi2_gain", stat, null));
  gm.found = null.fires(stat) && gm.fit.sigma_dps > 0.0;
  gm.extended_terms = gm.clean_fit.value;
  if (!gm.found) return gm;
  gm.extended_terms = gm.fit.terms_with_gm;
  DetectedEffect e;
  e.effect = ModelEffect::GaussMarkov;
  e.tau_s = gm.fit.tau_s;
  e.sigma_dps = gm.fit.sigma_dps;
  e.evidence = nullEvidence(stat, null, o.replicas);
  e.evidence.chi2_gain = gm.fit.improvement;
  e.evidence.chi2_base = gm.fit.chi2_base;
  out.effects.push_back(e);
  return gm;
}

}  // namespace gyrod::processing::model_check_detail
