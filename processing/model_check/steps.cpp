// The model check's low-frequency detector: a bias that follows the temperature against
// abrupt steps in the bias. Both show on the low-passed residual (block means, line removed),
// and either can explain the other away, so they are tested together and told apart.
#include <algorithm>
#include <cmath>
#include <limits>

#include "processing/base/detrend.hpp"
#include "processing/model_check/pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

constexpr std::size_t kMaxSteps = 8;
// Further looks at most (nullsAfterFurtherLooks).
constexpr std::size_t kMaxLooks = 6;
// The per-axis false-alarm budget (issue 13: at most 1 % of clean axes with any effect) is
// spent where power is short: the step statistic gets 10 × the nominal α of a statistic
// (1e-3 at the default 1e-4). Its null is the maximum over scales and positions of a Haar
// difference standardised by the base model's sd at its scale (stepScanStatistic), which
// the Gumbel model of the thresholds fits (clean-data rates in docs/model-check.md).
constexpr double kStepAlphaFactor = 10.0;
// Once one step is established, each further one is a question of how many, not whether:
// it passes at 1 % (against the same null, on the series with the steps found so far
// removed). Several steps of similar size otherwise fail one by one (five small steps in an
// hour came back as three).
constexpr double kFurtherStepAlpha = 1e-2;

struct BlockStep {
  std::size_t block = 0;  // the scan's boundary: the step is between block−1 and block
  std::size_t scale = 0;
  double size = 0.0;
  double at = 0.0;  // where the step is, in blocks (within blocks block−1 and block: placeStep)
  // The unit step's share of block i: a step inside a block leaves that block between the two
  // levels, and a whole-block regressor leaves up to half the step there, which the scan's
  // finest scales then take for a further step.
  double regressor(std::size_t i) const { return std::clamp(static_cast<double>(i) + 1.0 - at, 0.0, 1.0); }
  std::size_t sample(std::size_t block_length) const {
    return static_cast<std::size_t>(std::lround(at * static_cast<double>(block_length)));
  }
};

// Where within blocks b−1 .. b the step the scan found at boundary b is: the position (in
// tenths of a block) whose unit step, with a constant, fits the W blocks on either side best.
double placeStep(const std::vector<double>& r, const BlockStep& s) {
  const std::size_t w = std::max<std::size_t>(s.scale, 2);
  const std::size_t lo = s.block > w ? s.block - w : 0;
  const std::size_t hi = std::min(r.size(), s.block + w);
  BlockStep trial = s;
  double best_at = static_cast<double>(s.block), best_rss = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 20 && s.block >= 1; ++k) {
    trial.at = static_cast<double>(s.block) - 1.0 + 0.1 * k;
    double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, syy = 0.0;
    for (std::size_t i = lo; i < hi; ++i) {
      const double x = trial.regressor(i);
      n += 1.0;
      sx += x;
      sy += r[i];
      sxx += x * x;
      sxy += x * r[i];
      syy += r[i] * r[i];
    }
    const double vxx = sxx - sx * sx / n, vxy = sxy - sx * sy / n, vyy = syy - sy * sy / n;
    const double rss = vxx > 0.0 ? vyy - vxy * vxy / vxx : vyy;
    if (rss < best_rss) {
      best_rss = rss;
      best_at = trial.at;
    }
  }
  return best_at;
}

std::vector<double> blockRegression(const std::vector<double>& y, const std::vector<double>* temp,
                                    const std::vector<BlockStep>& steps, double& rss,
                                    std::vector<double>* residual = nullptr);

// y minus the steps and a line, all fitted jointly by least squares (the steps' sizes into
// `steps`). The line goes too: y had its line removed with the steps in it, and what the steps
// leave of that line would show at every position as a Haar difference of slope × W.
std::vector<double> withoutSteps(const std::vector<double>& y, std::vector<BlockStep>& steps) {
  double rss = 0.0;
  std::vector<double> r;
  const std::vector<double> sizes = blockRegression(y, nullptr, steps, rss, &r);
  for (std::size_t j = 0; j < steps.size(); ++j) steps[j].size = sizes[j];
  return r;
}

// The step scan: max over scales W and positions t of |D_W(t)| / sd_W, D_W(t) the mean of the
// W blocks from t minus the mean of the W before, sd_W its standard deviation under the base
// model (the root of the replicas' pooled mean square at that scale): the GLR of one step of
// unknown time and height at each scale, each difference standardised by the noise the
// model has at that scale (white, flicker, random walk, the chain; the line removal
// included), not by the series' own spread. Positions within W blocks of a step in `found`
// are left out at scale W: what a found step leaves behind (its size and place are
// estimates) must not count as a further step. Returns 0 without a scale of positive sd.
double stepScanStatistic(const std::vector<double>& y, const Context& c, const std::vector<double>& sd,
                         const std::vector<BlockStep>& found, BlockStep* where) {
  std::vector<double> prefix(y.size() + 1, 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) prefix[i + 1] = prefix[i] + y[i];
  double best = 0.0;
  for (std::size_t j = 0; j < c.scales.size() && j < sd.size(); ++j) {
    const std::size_t w = c.scales[j];
    if (2 * w > y.size() || !(sd[j] > 0.0)) continue;
    const double scale = 1.0 / (static_cast<double>(w) * sd[j]);
    for (std::size_t t = w; t + w <= y.size(); ++t) {
      const double d = (prefix[t + w] - 2.0 * prefix[t] + prefix[t - w]) * scale;
      if (std::fabs(d) <= best) continue;
      bool near = false;
      for (const BlockStep& f : found) near = near || (t + w > f.block && t < f.block + w);
      if (near) continue;
      best = std::fabs(d);
      if (where) *where = {t, w, d * sd[j]};
    }
  }
  return best;
}

// The standardised Haar difference of a step at its own boundary, largest over the scales,
// on the series without the other steps (their sizes fitted jointly with it): what the step
// shows once the others are accounted for.
double ownStepStatistic(const std::vector<double>& y, const Context& c, const std::vector<double>& sd,
                        const std::vector<BlockStep>& steps, std::size_t which) {
  std::vector<BlockStep> others;
  for (std::size_t j = 0; j < steps.size(); ++j)
    if (j != which) others.push_back(steps[j]);
  const std::vector<double> r = others.empty() ? y : withoutSteps(y, others);
  std::vector<double> prefix(r.size() + 1, 0.0);
  for (std::size_t i = 0; i < r.size(); ++i) prefix[i + 1] = prefix[i] + r[i];
  const std::size_t t = steps[which].block;
  double best = 0.0;
  for (std::size_t j = 0; j < c.scales.size() && j < sd.size(); ++j) {
    const std::size_t w = c.scales[j];
    if (t < w || t + w > r.size() || !(sd[j] > 0.0)) continue;
    const double d = (prefix[t + w] - 2.0 * prefix[t] + prefix[t - w]) / (static_cast<double>(w) * sd[j]);
    best = std::max(best, std::fabs(d));
  }
  return best;
}

// Backward elimination after the forward search: while the weakest step, given the others,
// does not pass (`further`, or `null` when it is the only one), it is dropped and the sizes
// refitted. A step found early can be the sum of two close ones, and a step found late can
// be what a misfitted neighbour leaves; both then fail at their own boundary.
void pruneBlockSteps(const std::vector<double>& y, const Context& c, const std::vector<double>& sd,
                     const NullSummary& null, const NullSummary& further, std::vector<BlockStep>& steps) {
  while (!steps.empty()) {
    std::size_t weakest = 0;
    double weakest_z = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < steps.size(); ++j) {
      const double z = ownStepStatistic(y, c, sd, steps, j);
      if (z < weakest_z) {
        weakest_z = z;
        weakest = j;
      }
    }
    if ((steps.size() == 1 ? null : further).fires(weakest_z)) break;
    steps.erase(steps.begin() + static_cast<std::ptrdiff_t>(weakest));
    if (!steps.empty()) withoutSteps(y, steps);
  }
}

// Steps one at a time: the largest standardised Haar difference while it passes the null
// (the first) or `further` (the others, away from those found), all sizes refitted jointly
// and removed from y before looking for the next: a Haar difference alone misjudges a step
// that has another within its window, and what it leaves behind looks like a further step.
std::vector<BlockStep> findBlockSteps(const std::vector<double>& y, const Context& c, const std::vector<double>& sd,
                                      const NullSummary& null, const NullSummary& further,
                                      std::vector<BlockStep> steps = {}) {
  std::vector<double> r = steps.empty() ? y : withoutSteps(y, steps);
  while (steps.size() < kMaxSteps) {
    BlockStep next;
    const double s = stepScanStatistic(r, c, sd, steps, &next);
    if (!(steps.empty() ? null : further).fires(s)) break;
    next.at = placeStep(r, next);
    steps.push_back(next);
    r = withoutSteps(y, steps);
  }
  pruneBlockSteps(y, c, sd, null, further, steps);
  std::sort(steps.begin(), steps.end(), [](const BlockStep& a, const BlockStep& b) { return a.block < b.block; });
  return steps;
}

// Least squares of y on [1, index, (temperature), (a unit step at each block)], returning
// the coefficients after the first two and the residual sum of squares.
std::vector<double> blockRegression(const std::vector<double>& y, const std::vector<double>* temp,
                                    const std::vector<BlockStep>& steps, double& rss, std::vector<double>* residual) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const Eigen::Index cols = 2 + (temp ? 1 : 0) + static_cast<Eigen::Index>(steps.size());
  Eigen::MatrixXd a(n, cols);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    Eigen::Index col = 0;
    a(i, col++) = 1.0;
    a(i, col++) = static_cast<double>(i) / static_cast<double>(n);
    if (temp) a(i, col++) = (*temp)[u];
    for (const BlockStep& s : steps) a(i, col++) = s.regressor(u);
    b(i) = y[u];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd e = b - a * x;
  rss = e.squaredNorm();
  if (residual) residual->assign(e.data(), e.data() + n);
  return std::vector<double>(x.data() + 2, x.data() + cols);
}

struct LowFrequencyNulls {
  NullSummary temp;
  std::vector<double> step_sd;  // sd of D_W per scale under the base model (the replicas')
  NullSummary steps;            // of stepScanStatistic, at the steps' share of the budget
  NullSummary further_steps;    // the same null at kFurtherStepAlpha
};

LowFrequencyNulls lowFrequencyNulls(const std::vector<SeriesStats>& reps, const Context& c, double alpha, bool temp,
                                    bool steps) {
  LowFrequencyNulls n;
  if (temp) n.temp = summarizeNull(column(reps, &SeriesStats::temp_slope), alpha, true);
  if (!steps) return n;
  // Pooled over the replicas and positions: the sd of D_W is then known to a few per cent
  // (40 replicas × 100–3000 positions) where one series' own spread is not at the wide
  // scales (a few dozen independent differences in 10 minutes, some of them the step's).
  n.step_sd.assign(c.scales.size(), 0.0);
  for (std::size_t j = 0; j < c.scales.size(); ++j) {
    double sum = 0.0;
    std::size_t count = 0;
    for (const SeriesStats& r : reps)
      if (j < r.step_scale_ms.size() && std::isfinite(r.step_scale_ms[j])) {
        sum += r.step_scale_ms[j];
        ++count;
      }
    n.step_sd[j] = count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
  }
  std::vector<double> maxes;
  maxes.reserve(reps.size());
  for (const SeriesStats& r : reps) {
    double m = 0.0;
    for (std::size_t j = 0; j < n.step_sd.size() && j < r.step_scale_max.size(); ++j)
      if (n.step_sd[j] > 0.0) m = std::max(m, r.step_scale_max[j] / n.step_sd[j]);
    maxes.push_back(m);
  }
  n.steps = summarizeNull(maxes, alpha * kStepAlphaFactor, false);
  // The Gumbel quantile alone: at 1 % the largest of a few dozen replicas would set it instead.
  n.further_steps = n.steps;
  const double further_alpha = std::max(kFurtherStepAlpha, alpha * kStepAlphaFactor);
  n.further_steps.threshold = n.steps.median + n.steps.spread * (-std::log(-std::log1p(-further_alpha)) - 0.3665);
  return n;
}

// The sample where a step found at block resolution is: the split within ±1 block that
// maximises the difference of the means of `half` samples on each side.
std::size_t refineStepSample(std::span<const double> r, std::size_t block_start, std::size_t block, std::size_t half) {
  const std::size_t n = r.size();
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + r[i];
  const std::size_t lo = block_start > block ? block_start - block : 1;
  const std::size_t hi = std::min(n - 1, block_start + block);
  std::size_t best = block_start;
  double best_d = -1.0;
  for (std::size_t i = std::max<std::size_t>(lo, 1); i <= hi; ++i) {
    const std::size_t w = std::min({half, i, n - i});
    if (w == 0) continue;
    const double d = std::fabs((prefix[i + w] - prefix[i]) - (prefix[i] - prefix[i - w])) / static_cast<double>(w);
    if (d > best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// The suggestive candidates of one look: steps beyond 2 spreads of the step null, continuing
// from those of the looks before (`kept`), found on the residual first (a temperature slope
// fitted with steps in the record takes up part of them, most in a warm-up), then the
// temperature slope of what the steps leave; when that slope is suggestive, further steps on
// the residual without it. `k` is the slope.
std::vector<BlockStep> suggestiveCandidates(const std::vector<double>& y, const Context& c, const LowFrequencyNulls& lf,
                                            const std::vector<BlockStep>& kept, bool have_temp, double& k,
                                            bool& temp_suggestive) {
  NullSummary lowered = lf.steps;
  lowered.threshold = lowered.median + 2.0 * lowered.spread;
  const bool have_steps = !lf.step_sd.empty();
  std::vector<BlockStep> candidates = have_steps ? findBlockSteps(y, c, lf.step_sd, lowered, lowered, kept) : kept;
  if (!have_temp) return candidates;
  std::vector<BlockStep> fitted = candidates;
  k = temperatureSlope(candidates.empty() ? y : withoutSteps(y, fitted), c.temp_blocks);
  temp_suggestive = lf.temp.excess(k) > 2.0;
  if (!temp_suggestive || !have_steps) return candidates;
  std::vector<double> r = y;
  for (std::size_t i = 0; i < r.size(); ++i) r[i] -= k * c.temp_blocks[i];
  return findBlockSteps(r, c, lf.step_sd, lowered, lowered, candidates);
}

// Further looks when a low-frequency statistic is suggestive (beyond 2 spreads of its
// null): a temperature response or steps in the data inflate the fitted rate random walk
// and ramp, and so widen the very null they are tested against. Refit the base model on
// the series with the suggestive candidates removed (a regression and a few steps: a few
// degrees of freedom of the slow noise) and test again against replicas of that fit;
// repeat while the candidates change (at most 3 looks). Clean data rarely get here,
// and then the refit changes little. Returns the nulls to test against; `looked` tells
// whether they come from a further look.
LowFrequencyNulls nullsAfterFurtherLooks(const std::vector<double>& xc, const Context& c,
                                         const std::vector<double>& temp_smoothed, LowFrequencyNulls lf,
                                         const ModelCheckOptions& o, AxisModelCheck& out, bool& looked) {
  const bool have_temp = !c.temp_blocks.empty();
  const bool have_steps = !c.scales.empty();
  std::size_t previous_signature = 0;
  const std::vector<double> y = lowPassedResidual(xc, c);
  std::vector<BlockStep> candidates;
  for (std::size_t look = 0; look < kMaxLooks; ++look) {
    double k = 0.0;
    bool temp_suggestive = false;
    candidates = suggestiveCandidates(y, c, lf, candidates, have_temp, k, temp_suggestive);
    const std::size_t signature = (temp_suggestive ? 1 : 0) + 2 * (candidates.size() + 1);
    if (!temp_suggestive && candidates.empty()) break;
    if (signature == previous_signature) break;
    previous_signature = signature;
    std::vector<double> alt = xc;
    if (temp_suggestive)
      for (std::size_t i = 0; i < alt.size(); ++i) alt[i] -= k * temp_smoothed[i];
    for (const BlockStep& st : candidates)
      for (std::size_t i = st.sample(c.block); i < alt.size(); ++i) alt[i] -= st.size;
    removeLinearTrend(alt, c.tau0);
    const NoiseTermFit alt_fit = fitNoiseTerms(allanDeviationTable(alt, c.tau0, c.ms));
    const std::vector<SeriesStats> reps = runReplicas(pureModel(c.rate, alt_fit.value), statisticalUncertainty(alt_fit),
                                                      c, {}, o, 4 + look, kStatTemperature | kStatSteps);
    out.replicas_simulated += o.replicas;
    lf = lowFrequencyNulls(reps, c, o.false_alarm, have_temp, have_steps);
    looked = true;
  }
  return lf;
}

// The two explanations of the low-passed residual against their nulls.
struct LowFrequencyTests {
  const Context& c;
  const LowFrequencyNulls& nulls;
  bool have_temp, have_steps;

  bool temperatureFires(const std::vector<double>& y) const {
    return have_temp && nulls.temp.fires(temperatureSlope(y, c.temp_blocks));
  }
  bool stepsFire(const std::vector<double>& y) const {
    return have_steps && nulls.steps.fires(stepScanStatistic(y, c, nulls.step_sd, {}, nullptr));
  }
  std::vector<double> minusTemperature(const std::vector<double>& y) const {
    std::vector<double> r = y;
    const double k = temperatureSlope(y, c.temp_blocks);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] -= k * c.temp_blocks[i];
    return r;
  }
  std::vector<double> minusSteps(const std::vector<double>& y, std::vector<BlockStep> steps) const {
    return withoutSteps(y, steps);
  }
  std::vector<BlockStep> steps(const std::vector<double>& y) const {
    return findBlockSteps(y, c, nulls.step_sd, nulls.steps, nulls.further_steps);
  }
};

struct LowFrequencyChoice {
  bool temperature = false;
  std::vector<BlockStep> steps;
  LowFrequencyDecision decision = LowFrequencyDecision::None;
  double bic_temperature = 0.0, bic_steps = 0.0;
};

// Both fire: remove each and see whether the other still holds.
LowFrequencyChoice chooseWhenBothFire(const std::vector<double>& y0, const LowFrequencyTests& tests) {
  LowFrequencyChoice ch;
  const std::vector<double> r_t = tests.minusTemperature(y0);
  const bool steps_after_t = tests.stepsFire(r_t);
  const std::vector<BlockStep> steps0 = tests.steps(y0);
  const bool temp_after_s = !steps0.empty() && tests.temperatureFires(tests.minusSteps(y0, steps0));
  if (steps_after_t && temp_after_s) {
    ch.temperature = true;
    ch.steps = tests.steps(r_t);
    ch.decision = LowFrequencyDecision::EachRemains;
  } else if (steps_after_t) {
    ch.steps = steps0;
    ch.decision = LowFrequencyDecision::TemperatureVanishes;
  } else if (temp_after_s) {
    ch.temperature = true;
    ch.decision = LowFrequencyDecision::StepsVanish;
  } else {
    // Each explains the other away: the penalised likelihood (BIC) of the two models of
    // the low-passed residual decides; a step is abrupt, a temperature response smooth.
    double rss_t = 0.0, rss_s = 0.0;
    blockRegression(y0, &tests.c.temp_blocks, {}, rss_t);
    blockRegression(y0, nullptr, steps0, rss_s);
    const double nb = static_cast<double>(y0.size());
    ch.bic_temperature = nb * std::log(rss_t / nb) + 1.0 * std::log(nb);
    ch.bic_steps = nb * std::log(rss_s / nb) + 2.0 * static_cast<double>(steps0.size()) * std::log(nb);
    if (ch.bic_temperature <= ch.bic_steps) {
      ch.temperature = true;
    } else {
      ch.steps = steps0;
    }
    ch.decision = LowFrequencyDecision::ByBic;
  }
  return ch;
}

LowFrequencyChoice chooseTemperatureOrSteps(const std::vector<double>& y0, const LowFrequencyTests& tests) {
  const bool a = tests.temperatureFires(y0), b = tests.stepsFire(y0);
  LowFrequencyChoice ch;
  if (a && !b) {
    ch.temperature = true;
    const std::vector<double> r = tests.minusTemperature(y0);
    if (tests.stepsFire(r)) ch.steps = tests.steps(r);
    ch.decision = ch.steps.empty() ? LowFrequencyDecision::TemperatureOnly : LowFrequencyDecision::TemperatureThenSteps;
  } else if (!a && b) {
    ch.steps = tests.steps(y0);
    ch.temperature = !ch.steps.empty() && tests.temperatureFires(tests.minusSteps(y0, ch.steps));
    ch.decision = ch.temperature ? LowFrequencyDecision::StepsThenTemperature : LowFrequencyDecision::StepsOnly;
  } else if (a && b) {
    ch = chooseWhenBothFire(y0, tests);
  }
  return ch;
}

// The chosen temperature coefficient and step sizes fitted jointly on the low-passed
// residual, each step placed at its sample, into `removal`.
// The temperature part is subtracted with the smoothed channel (the extended model's
// regressor): the raw column's noise and 1/340 °C steps times k would add noise to r and
// move the refined step samples.
void fitChosenEffects(const std::vector<double>& y0, const std::vector<double>& xc, const Context& c,
                      const std::vector<double>& temp_smoothed, LowFrequencyChoice& ch, Removal& removal) {
  double rss = 0.0;
  const std::vector<double> coef = blockRegression(y0, ch.temperature ? &c.temp_blocks : nullptr, ch.steps, rss);
  std::size_t next = 0;
  if (ch.temperature) {
    removal.temperature = true;
    removal.k = coef[next++];
  }
  for (BlockStep& s : ch.steps) s.size = coef[next++];
  // Each step's sample, from the series with the temperature part and the other steps removed.
  std::vector<double> r = xc;
  if (ch.temperature)
    for (std::size_t i = 0; i < r.size(); ++i) r[i] -= removal.k * temp_smoothed[i];
  for (const BlockStep& s : ch.steps)
    for (std::size_t i = s.sample(c.block); i < r.size(); ++i) r[i] -= s.size;
  for (const BlockStep& s : ch.steps) {
    for (std::size_t i = s.sample(c.block); i < r.size(); ++i) r[i] += s.size;  // this one back
    const std::size_t at = refineStepSample(r, s.sample(c.block), c.block, s.scale * c.block);
    for (std::size_t i = at; i < r.size(); ++i) r[i] -= s.size;
    removal.step_samples.push_back(at);
    removal.step_sizes.push_back(s.size);
  }
}

EffectEvidence lowFrequencyEvidence(double value, const NullSummary& null, std::size_t replicas,
                                    const LowFrequencyChoice& ch) {
  EffectEvidence e = nullEvidence(value, null, replicas);
  e.decision = ch.decision;
  e.bic_temperature = ch.bic_temperature;
  e.bic_steps = ch.bic_steps;
  return e;
}

}  // namespace

void measureStepScales(const std::vector<double>& y, const Context& c, SeriesStats& s) {
  s.step_scale_max.assign(c.scales.size(), 0.0);
  s.step_scale_ms.assign(c.scales.size(), kNaN);
  for (std::size_t j = 0; j < c.scales.size(); ++j) {
    const HaarScan h = haarScan(y, c.scales[j]);
    if (h.count == 0) continue;
    s.step_scale_max[j] = h.max_abs;
    s.step_scale_ms[j] = h.sum_squares / static_cast<double>(h.count);
  }
}

bool checkTemperatureAndSteps(const AxisModelCheckInput& input, std::vector<double>& xc, const Context& c,
                              const TemperatureChannel& temp, const std::vector<SeriesStats>& base_reps,
                              const ModelCheckOptions& o, Removal& removal, AxisModelCheck& out) {
  const bool have_temp = !c.temp_blocks.empty();
  const bool have_steps = !c.scales.empty();
  bool second_look = false;
  const LowFrequencyNulls lf = nullsAfterFurtherLooks(
      xc, c, temp.smoothed, lowFrequencyNulls(base_reps, c, o.false_alarm, have_temp, have_steps), o, out, second_look);
  const std::vector<double> y0 = lowPassedResidual(xc, c);
  out.block_residual_dps = y0;
  out.block_temperature_c = temp.raw_blocks;
  out.block_temperature_c.resize(std::min(temp.raw_blocks.size(), y0.size()));

  const double t_stat = have_temp ? temperatureSlope(y0, c.temp_blocks) : kNaN;
  const double s_stat = have_steps ? stepScanStatistic(y0, c, lf.step_sd, {}, nullptr) : kNaN;
  const std::string look = second_look ? " (second look)" : "";
  if (have_temp) out.statistics.push_back(makeStatistic("temperature_slope_dps_per_c" + look, t_stat, lf.temp));
  if (have_steps) out.statistics.push_back(makeStatistic("step_scan_max_z" + look, s_stat, lf.steps));
  LowFrequencyChoice ch = chooseTemperatureOrSteps(y0, {c, lf, have_temp, have_steps});
  if (!ch.temperature && ch.steps.empty()) return false;

  fitChosenEffects(y0, xc, c, temp.smoothed, ch, removal);
  if (ch.temperature) {
    DetectedEffect e;
    e.effect = ModelEffect::TemperatureBias;
    e.k_dps_per_c = removal.k;
    e.evidence = lowFrequencyEvidence(t_stat, lf.temp, o.replicas, ch);
    out.effects.push_back(e);
  }
  if (!ch.steps.empty()) {
    DetectedEffect e;
    e.effect = ModelEffect::BiasSteps;
    e.count = ch.steps.size();
    for (std::size_t j = 0; j < removal.step_samples.size(); ++j) {
      const std::size_t i = removal.step_samples[j];
      e.times_s.push_back(input.time_s.empty() ? static_cast<double>(i) * c.tau0 : input.time_s[i]);
      e.sizes_dps.push_back(removal.step_sizes[j]);
    }
    e.evidence = lowFrequencyEvidence(s_stat, lf.steps, o.replicas, ch);
    out.effects.push_back(e);
  }
  Removal low_frequency;  // the temperature response and the steps: the lines are already out of xc
  low_frequency.k = removal.k;
  low_frequency.temperature = removal.temperature;
  low_frequency.step_samples = removal.step_samples;
  low_frequency.step_sizes = removal.step_sizes;
  const std::vector<double> d = deterministicPart(low_frequency, xc.size(), c.rate, temp.smoothed);
  for (std::size_t i = 0; i < xc.size(); ++i) xc[i] -= d[i];
  return true;
}

}  // namespace gyrod::processing::model_check_detail
