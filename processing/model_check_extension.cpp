// The model check's extended model: the refitted terms plus every named effect, simulated
// again; what its replicas still do not cover (unexplained), and the gain over the base model
// in the Allan band and in the Kalman filter's innovations.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "processing/ar_model.hpp"
#include "processing/detrend.hpp"
#include "processing/model_check_pipeline.hpp"

namespace gyrod::processing::model_check_detail {
namespace {

void bandFigures(const AllanBand& b, double& log_error, double& in_band) {
  double err = 0.0;
  std::size_t inside = 0;
  for (std::size_t j = 0; j < b.tau_s.size(); ++j) {
    err += std::fabs(std::log10(b.measured[j] / b.median[j]));
    inside += (b.measured[j] >= b.lo[j] && b.measured[j] <= b.hi[j]) ? 1 : 0;
  }
  log_error = err / static_cast<double>(b.tau_s.size());
  in_band = static_cast<double>(inside) / static_cast<double>(b.tau_s.size());
}

// The simulation model of the extended model: terms plus the named effects as extras.
SimulationModel extendedSimulationModel(const ExtensionInputs& in, double rate, double tau0) {
  const GaussMarkovFound& gm = *in.gauss_markov;
  SimulationModel ext = pureModel(rate, gm.extended_terms);
  AxisExtraEffects& extra = ext.axes[0].extra;
  for (const SinusoidFit& s : in.removal->sinusoids) extra.sinusoids.push_back({s.freq_hz, s.amp_dps, s.phase_rad});
  for (std::size_t j = 0; j < in.removal->step_samples.size(); ++j)
    extra.bias_steps.push_back({static_cast<double>(in.removal->step_samples[j]) * tau0, in.removal->step_sizes[j]});
  if (gm.found) {
    extra.gauss_markov_tau_s = gm.fit.tau_s;
    extra.gauss_markov_sigma_dps = gm.fit.sigma_dps;
  }
  extra.outlier_count = in.outliers.count;
  extra.outlier_amplitude_dps = in.outliers.median_amplitude;
  return ext;
}

// The Allan band of the extended model's replicas (the base band when nothing was named).
AllanNull extendedAllanNull(const ExtensionInputs& in, bool any_model_effect, const Context& c,
                            const ModelCheckOptions& o, AxisModelCheck& out) {
  if (!any_model_effect) return *in.base_allan;
  const SimulationModel ext = extendedSimulationModel(in, c.rate, c.tau0);
  // The measured temperature drives the replicas' temperature term: the simulator's own
  // warm-up curve is not the recording's.
  std::vector<double> added;
  if (in.removal->temperature) {
    added.resize(c.n);
    for (std::size_t i = 0; i < c.n; ++i) added[i] = in.removal->k * (*in.temp_detrended)[i];
  }
  const std::vector<SeriesStats> reps =
      runReplicas(ext, statisticalUncertainty(in.gauss_markov->clean_fit), c, added, o, 3, kStatAllan);
  out.replicas_simulated += o.replicas;
  return allanNull(reps, *in.measured_log_adev, c, o.false_alarm);
}

// Where the measured Allan deviation leaves the replicas' band, as an `unexplained` effect.
void checkUnexplained(const AllanNull& ext_allan, const std::vector<double>& measured_log_adev, bool any_model_effect,
                      const Context& c, std::size_t replicas, AxisModelCheck& out) {
  std::vector<double> z_ext;
  const double ext_max_z = maxAbsZ(measured_log_adev, ext_allan.median_log, ext_allan.spread_log, &z_ext);
  out.statistics.push_back(makeStatistic("allan_band_max_z_extended", ext_max_z, ext_allan.max_z));
  if (!ext_allan.max_z.fires(ext_max_z)) return;
  DetectedEffect e;
  e.effect = ModelEffect::Unexplained;
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (std::size_t j = 0; j < z_ext.size(); ++j)
    if (std::fabs(z_ext[j]) >= std::min(3.0, ext_max_z)) {
      lo = std::min(lo, c.taus[j]);
      hi = std::max(hi, c.taus[j]);
    }
  e.where_lo = lo;
  e.where_hi = hi;
  e.evidence = nullEvidence(ext_max_z, ext_allan.max_z, replicas);
  e.evidence.against_extended = any_model_effect;
  out.effects.push_back(e);
}

// The innovations of the extended model's Kalman filter: the measured series minus the
// deterministic effects (regressors); the AR part refitted on the cleaned series, with the
// Gauss–Markov autocovariance σ²ρ^k taken out of it when named.
void extendedInnovationGain(const ExtensionInputs& in, std::size_t max_order, const Context& c,
                            const ModelCheckOptions& o, ModelCheckGain& gain) {
  std::vector<double> z(in.xd.begin(), in.xd.end());
  const std::vector<double> d = deterministicPart(*in.removal, z.size(), c.rate, *in.temp_detrended);
  for (std::size_t i = 0; i < z.size(); ++i) z[i] -= d[i];
  removeLinearTrend(z, c.tau0);
  const std::vector<ArModel> ar_clean = yuleWalker(in.xc, max_order);
  const ArModel& clean_ar = ar_clean[orderByAic(ar_clean) - 1];
  std::vector<double> phi = clean_ar.phi;
  double noise_var = clean_ar.noise_var;
  double gm_decay = 0.0, gm_q = 0.0;
  const GaussMarkovFound& gm = *in.gauss_markov;
  if (gm.found) {
    const double rho = std::exp(-c.tau0 / gm.fit.tau_s);
    std::vector<double> gamma = autocovariance(in.xc, clean_ar.order());
    double var_gm = gm.fit.sigma_dps * gm.fit.sigma_dps;
    // Keep what is left positive definite: shrink the GM share if it takes too much.
    for (int attempt = 0; attempt < 20; ++attempt, var_gm *= 0.8) {
      std::vector<double> adj = gamma;
      for (std::size_t k = 0; k < adj.size(); ++k) adj[k] -= var_gm * std::pow(rho, static_cast<double>(k));
      std::vector<double> phi_adj;
      double v_adj = 0.0;
      if (levinsonFromAutocovariance(adj, clean_ar.order(), phi_adj, v_adj)) {
        phi = phi_adj;
        noise_var = v_adj;
        gm_decay = rho;
        gm_q = var_gm * (1.0 - rho * rho);
        break;
      }
    }
  }
  const InnovationStats inn_ext = kalmanInnovations(z, phi, noise_var, gm_decay, gm_q, in.outliers.count > 0);
  gain.innovation_var_extended = inn_ext.variance;
  gain.ljung_box_p_extended =
      ljungBoxTest(inn_ext.innovations, o.ljung_box_lags, phi.size() + (gm_q > 0.0 ? 2 : 0)).p_value;
}

}  // namespace

std::vector<double> deterministicPart(const Removal& r, std::size_t n, double rate,
                                      const std::vector<double>& temp_detrended) {
  std::vector<double> d(n, 0.0);
  for (const SinusoidFit& s : r.sinusoids) {
    const double w = 2.0 * std::numbers::pi * s.freq_hz / rate;
    for (std::size_t i = 0; i < n; ++i) d[i] += s.amp_dps * std::sin(w * static_cast<double>(i) + s.phase_rad);
  }
  if (r.temperature)
    for (std::size_t i = 0; i < n; ++i) d[i] += r.k * temp_detrended[i];
  for (std::size_t j = 0; j < r.step_samples.size(); ++j)
    for (std::size_t i = r.step_samples[j]; i < n; ++i) d[i] += r.step_sizes[j];
  return d;
}

void checkExtendedModel(const ExtensionInputs& in, const Context& c, const ModelCheckOptions& o, AxisModelCheck& out) {
  const bool any_model_effect = in.deterministic_found || in.gauss_markov->found;
  const AllanNull ext_allan = extendedAllanNull(in, any_model_effect, c, o, out);
  out.allan_extended = ext_allan.band;
  checkUnexplained(ext_allan, *in.measured_log_adev, any_model_effect, c, o.replicas, out);

  bandFigures(out.allan_base, out.gain.adev_log_error_base, out.gain.in_band_base);
  bandFigures(out.allan_extended, out.gain.adev_log_error_extended, out.gain.in_band_extended);

  const std::size_t max_order = std::min(o.max_ar_order, in.xd.size() / 10);
  const std::vector<ArModel> ar_base = yuleWalker(in.xd, max_order);
  const ArModel& base_ar = ar_base[orderByAic(ar_base) - 1];
  out.ar_order = base_ar.order();
  const InnovationStats inn_base = kalmanInnovations(in.xd, base_ar.phi, base_ar.noise_var, 0.0, 0.0, false);
  out.gain.innovation_var_base = inn_base.variance;
  out.gain.ljung_box_p_base = ljungBoxTest(inn_base.innovations, o.ljung_box_lags, base_ar.order()).p_value;

  if (any_model_effect) {
    extendedInnovationGain(in, max_order, c, o, out.gain);
  } else {
    out.gain.innovation_var_extended = out.gain.innovation_var_base;
    out.gain.ljung_box_p_extended = out.gain.ljung_box_p_base;
  }
}

}  // namespace gyrod::processing::model_check_detail
