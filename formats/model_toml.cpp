#include "formats/model_toml.hpp"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "formats/input_file.hpp"
#include "formats/toml_document.hpp"

namespace gyrod::recording {
namespace {

using processing::SimulationModel;

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

using formats::tomlTypeName;

// The model's keys and checks on top of the TOML reader, which reports every problem as
// "FILE:LINE: cause" at the key's line.
class ModelReader {
 public:
  explicit ModelReader(const formats::TomlDocument& doc) : doc_(doc) {}

  [[noreturn]] void fail(const toml::source_region& where, const std::string& cause) const { doc_.fail(where, cause); }

  double number(const toml::node& node, const toml::key& key, const std::string& where) const {
    if (!node.is_number())
      fail(key.source(), where + std::string(key.str()) + " must be a number, got " + tomlTypeName(node));
    const double v = *node.value<double>();
    if (!std::isfinite(v))
      fail(key.source(), where + std::string(key.str()) + " must be finite, got " + formatNumber(v));
    return v;
  }
  double nonNegative(const toml::node& node, const toml::key& key, const std::string& where) const {
    const double v = number(node, key, where);
    if (v < 0.0) fail(key.source(), where + std::string(key.str()) + " must be >= 0, got " + formatNumber(v));
    return v;
  }
  double positive(const toml::node& node, const toml::key& key, const std::string& where) const {
    const double v = number(node, key, where);
    if (!(v > 0.0)) fail(key.source(), where + std::string(key.str()) + " must be > 0, got " + formatNumber(v));
    return v;
  }
  int integerIn(const toml::node& node, const toml::key& key, int lo, int hi) const {
    if (!node.is_integer())
      fail(key.source(), std::string(key.str()) + " must be an integer, got " + tomlTypeName(node));
    const std::int64_t v = *node.value<std::int64_t>();
    if (v < lo || v > hi)
      fail(key.source(), std::string(key.str()) + " must be " + std::to_string(lo) + ".." + std::to_string(hi) +
                             ", got " + formatNumber(v));
    return static_cast<int>(v);
  }
  const toml::table& table(const toml::node& node, const toml::key& key) const {
    if (!node.is_table())
      fail(key.source(),
           std::string(key.str()) + " must be a table ([" + std::string(key.str()) + "]), got " + tomlTypeName(node));
    return *node.as_table();
  }

  SensorModel read(const toml::table& root) const {
    SensorModel sensor;
    SimulationModel& model = sensor.simulation;
    const toml::key* rate_key = nullptr;
    // The rate bounds the narrowband lines' centres, which may be read before rate_hz itself.
    if (const toml::node* rate = root.get("rate_hz"); rate && rate->is_number()) {
      const double v = *rate->value<double>();
      line_rate_hz_ = std::isfinite(v) && v > 0.0 ? v : 0.0;  // 0: rate_hz's own error comes first
      line_rate_given_ = true;
    }
    for (auto&& [key, node] : root) {
      const std::string k(key.str());
      if (k == "rate_hz") {
        model.rate_hz = positive(node, key, "");
        rate_key = &key;
      } else if (k == "dlpf") {
        model.dlpf_cfg = integerIn(node, key, 0, 6);
      } else if (k == "fs_sel") {
        model.fs_sel = integerIn(node, key, 0, 3);
      } else if (k == "temperature") {
        readTemperature(table(node, key), model.temperature);
      } else if (k == "x" || k == "y" || k == "z") {
        readAxis(table(node, key), k, sensor, static_cast<std::size_t>(k[0] - 'x'));
      } else if (k == "filter") {
        sensor.filter = readFilter(table(node, key));
      } else {
        fail(key.source(),
             "unknown key '" + k + "' (expected rate_hz, dlpf, fs_sel, [temperature], [x], [y], [z], [filter])");
      }
    }
    if (model.dlpf_cfg) {
      try {
        processing::sampleRateDivisor(*model.dlpf_cfg, model.rate_hz);
      } catch (const std::invalid_argument& e) {
        if (rate_key) fail(rate_key->source(), e.what());
        doc_.failFile(e.what() + std::string(" (rate_hz not given: default 50)"));
      }
    }
    return sensor;
  }

  void readTemperature(const toml::table& t, processing::TemperatureModel& temp) const {
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (k == "start_c")
        temp.start_c = number(node, key, "temperature.");
      else if (k == "final_c")
        temp.final_c = number(node, key, "temperature.");
      else if (k == "time_constant_s")
        temp.time_constant_s = positive(node, key, "temperature.");
      else if (k == "noise_std_c")
        temp.noise_std_c = nonNegative(node, key, "temperature.");
      else
        fail(key.source(),
             "unknown key '" + k + "' in [temperature] (expected start_c, final_c, time_constant_s, noise_std_c)");
    }
  }

  void readAxis(const toml::table& t, const std::string& axis, SensorModel& sensor, std::size_t slot) const {
    processing::AxisNoiseModel& out = sensor.simulation.axes[slot];
    const std::string where = axis + ".";
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      bool is_term = false;
      for (processing::NoiseTerm term : processing::kAllNoiseTerms) {
        if (k == processing::noiseTermKey(term)) {
          out.terms.set(term, nonNegative(node, key, where));
          is_term = true;
        }
      }
      if (is_term) continue;
      if (k == "bias_dps") {
        out.bias_dps = number(node, key, where);
      } else if (k == "ar") {
        readAr(table(node, key), axis, out.ar);
      } else if (k == "extra") {
        readExtra(table(node, key), axis, out.extra);
      } else if (k == "calibration") {
        sensor.calibration[slot] = readCalibration(table(node, key), axis);
      } else if (k == "kalman") {
        sensor.kalman[slot] = readKalman(table(node, key), axis);
      } else {
        fail(key.source(), "unknown key '" + k + "' in [" + axis +
                               "] (expected the five noise-term keys of noise_terms.hpp, bias_dps, [" + axis +
                               ".ar], [" + axis + ".extra], [" + axis + ".calibration], [" + axis + ".kalman])");
      }
    }
  }

  // [x.extra]: the optional effects of the model check (processing::AxisExtraEffects).
  //   temperature_coefficient_dps_per_c, temperature_reference_c, gauss_markov_tau_s,
  //   gauss_markov_sigma_dps, outlier_count, outlier_amplitude_dps,
  //   sinusoids = [{freq_hz = 1.0, amp_dps = 0.05, phase_rad = 0.0}, ...],
  //   bias_steps = [{time_s = 60.0, size_dps = 0.02}, ...],
  //   narrowband_lines = [{centre_hz = 31.4, width_hz = 0.3, rms_dps = 0.02}, ...]
  void readExtra(const toml::table& t, const std::string& axis, processing::AxisExtraEffects& e) const {
    const std::string where = axis + ".extra.";
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (k == "temperature_coefficient_dps_per_c")
        e.temperature_coefficient_dps_per_c = number(node, key, where);
      else if (k == "temperature_reference_c")
        e.temperature_reference_c = number(node, key, where);
      else if (k == "gauss_markov_tau_s")
        e.gauss_markov_tau_s = nonNegative(node, key, where);
      else if (k == "gauss_markov_sigma_dps")
        e.gauss_markov_sigma_dps = nonNegative(node, key, where);
      else if (k == "outlier_amplitude_dps")
        e.outlier_amplitude_dps = nonNegative(node, key, where);
      else if (k == "outlier_count")
        e.outlier_count = static_cast<std::size_t>(integerIn(node, key, 0, 1000000000));
      else if (k == "sinusoids" || k == "bias_steps" || k == "narrowband_lines") {
        if (!node.is_array())
          fail(key.source(), where + k + " must be an array of inline tables, got " + tomlTypeName(node));
        for (const toml::node& element : *node.as_array()) {
          if (!element.is_table())
            fail(key.source(), where + k + " must contain inline tables only, found " + tomlTypeName(element));
          if (k == "sinusoids") {
            processing::SinusoidEffect sin;
            for (auto&& [ek, ev] : *element.as_table()) {
              const std::string n(ek.str());
              if (n == "freq_hz")
                sin.freq_hz = positive(ev, ek, where + "sinusoids.");
              else if (n == "amp_dps")
                sin.amp_dps = nonNegative(ev, ek, where + "sinusoids.");
              else if (n == "phase_rad")
                sin.phase_rad = number(ev, ek, where + "sinusoids.");
              else
                fail(ek.source(),
                     "unknown key '" + n + "' in " + where + "sinusoids (expected freq_hz, amp_dps, phase_rad)");
            }
            e.sinusoids.push_back(sin);
          } else if (k == "narrowband_lines") {
            e.narrowband_lines.push_back(readNarrowbandLine(*element.as_table(), key, where));
          } else {
            processing::BiasStepEffect step;
            for (auto&& [ek, ev] : *element.as_table()) {
              const std::string n(ek.str());
              if (n == "time_s")
                step.time_s = nonNegative(ev, ek, where + "bias_steps.");
              else if (n == "size_dps")
                step.size_dps = number(ev, ek, where + "bias_steps.");
              else
                fail(ek.source(), "unknown key '" + n + "' in " + where + "bias_steps (expected time_s, size_dps)");
            }
            e.bias_steps.push_back(step);
          }
        }
      } else {
        fail(key.source(), "unknown key '" + k + "' in [" + axis +
                               ".extra] (expected temperature_coefficient_dps_per_c, temperature_reference_c, "
                               "gauss_markov_tau_s, gauss_markov_sigma_dps, outlier_count, outlier_amplitude_dps, "
                               "sinusoids, bias_steps, narrowband_lines)");
      }
    }
    try {
      processing::validateExtraEffects(e, axis + ".");
    } catch (const std::invalid_argument& ex) {
      doc_.failFile(ex.what());
    }
  }

  // One element of narrowband_lines: centre_hz and width_hz required, rms_dps 0 by default; the
  // centre below the Nyquist frequency of the file's rate (the default 50 Hz when it gives none).
  processing::NarrowbandLine readNarrowbandLine(const toml::table& t, const toml::key& array_key,
                                                const std::string& where) const {
    const std::string in = where + "narrowband_lines.";
    processing::NarrowbandLine line;
    for (auto&& [key, node] : t) {
      const std::string n(key.str());
      if (n == "centre_hz") {
        line.centre_hz = positive(node, key, in);
        if (line_rate_hz_ > 0.0 && !(line.centre_hz < line_rate_hz_ / 2.0))
          fail(key.source(), in + "centre_hz must be < rate_hz/2 = " + formatNumber(line_rate_hz_ / 2.0) + ", got " +
                                 formatNumber(line.centre_hz) +
                                 (line_rate_given_ ? "" : " (rate_hz not given: default 50)"));
      } else if (n == "width_hz") {
        line.width_hz = positive(node, key, in);
      } else if (n == "rms_dps") {
        line.rms_dps = nonNegative(node, key, in);
      } else {
        fail(key.source(),
             "unknown key '" + n + "' in " + where + "narrowband_lines (expected centre_hz, width_hz, rms_dps)");
      }
    }
    for (const char* needed : {"centre_hz", "width_hz"})
      if (!t.contains(needed))
        fail(array_key.source(),
             where + "narrowband_lines: each line needs centre_hz and width_hz (" + needed + " is missing)");
    return line;
  }

  // [x.calibration]: every key optional (AxisCalibration's defaults).
  AxisCalibration readCalibration(const toml::table& t, const std::string& axis) const {
    const std::string where = axis + ".calibration.";
    AxisCalibration c;
    const toml::key* amplitude_key = nullptr;
    bool time_constant_given = false;
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (k == "bias_std_dps") {
        c.bias_std_dps = nonNegative(node, key, where);
      } else if (k == "temperature_coefficient_dps_per_c") {
        c.temperature_coefficient_dps_per_c = number(node, key, where);
      } else if (k == "temperature_coefficient_std_dps_per_c") {
        c.temperature_coefficient_std_dps_per_c = nonNegative(node, key, where);
      } else if (k == "temperature_reference_c") {
        c.temperature_reference_c = number(node, key, where);
      } else if (k == "warm_up_amplitude_dps") {
        c.warm_up_amplitude_dps = number(node, key, where);
        amplitude_key = &key;
      } else if (k == "warm_up_amplitude_std_dps") {
        c.warm_up_amplitude_std_dps = nonNegative(node, key, where);
      } else if (k == "warm_up_time_constant_s") {
        c.warm_up_time_constant_s = positive(node, key, where);
        time_constant_given = true;
      } else {
        fail(key.source(), "unknown key '" + k + "' in [" + axis +
                               ".calibration] (expected bias_std_dps, temperature_coefficient_dps_per_c, "
                               "temperature_coefficient_std_dps_per_c, temperature_reference_c, "
                               "warm_up_amplitude_dps, warm_up_amplitude_std_dps, warm_up_time_constant_s)");
      }
    }
    if (amplitude_key && c.warm_up_amplitude_dps != 0.0 && !time_constant_given)
      fail(amplitude_key->source(), where + "warm_up_amplitude_dps needs warm_up_time_constant_s");
    return c;
  }

  // [x.kalman]: a, q, r as gyrod's [filter.kalman] takes them.
  processing::ScalarKalmanParameters readKalman(const toml::table& t, const std::string& axis) const {
    const std::string where = axis + ".kalman.";
    processing::ScalarKalmanParameters k;
    for (auto&& [key, node] : t) {
      const std::string name(key.str());
      if (name == "a") {
        k.a = number(node, key, where);
        if (!(std::fabs(k.a) <= 1.0)) fail(key.source(), where + "a must be in [-1, 1], got " + formatNumber(k.a));
      } else if (name == "q") {
        k.q = nonNegative(node, key, where);
      } else if (name == "r") {
        k.r = positive(node, key, where);
      } else {
        fail(key.source(), "unknown key '" + name + "' in [" + axis + ".kalman] (expected a, q, r)");
      }
    }
    // A filter without one of them is no filter (R = 0 is refused by the Kalman filter itself).
    for (const char* needed : {"a", "q", "r"})
      if (!t.contains(needed)) fail(t.source(), "[" + axis + ".kalman] needs a, q and r (" + needed + " is missing)");
    return k;
  }

  // [filter]: every key optional (FilterModel's defaults).
  FilterModel readFilter(const toml::table& t) const {
    const std::string where = "filter.";
    FilterModel f;
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (k == "mean_window") {
        f.mean_window = static_cast<std::size_t>(integerIn(node, key, 1, 100000));
      } else if (k == "mean_threshold_dps") {
        f.mean_threshold_dps = positive(node, key, where);
      } else if (k == "still_window_samples") {
        f.still.window_samples = static_cast<std::size_t>(integerIn(node, key, 3, 100000));
      } else if (k == "still_mean_threshold_sigmas") {
        f.still.mean_threshold_sigmas = positive(node, key, where);
      } else if (k == "still_difference_false_alarm") {
        f.still.difference_false_alarm = positive(node, key, where);
        if (!(f.still.difference_false_alarm < 1.0))
          fail(key.source(), where + k + " must be < 1, got " + formatNumber(f.still.difference_false_alarm));
      } else if (k == "bias_instability_horizon_s") {
        f.bias_instability_horizon_s = positive(node, key, where);
      } else if (k == "temperature_smoothing_s") {
        f.temperature_smoothing_s = nonNegative(node, key, where);
      } else if (k == "low_pass_hz") {
        f.low_pass_hz = positive(node, key, where);
      } else {
        fail(key.source(), "unknown key '" + k +
                               "' in [filter] (expected mean_window, mean_threshold_dps, still_window_samples, "
                               "still_mean_threshold_sigmas, still_difference_false_alarm, "
                               "bias_instability_horizon_s, temperature_smoothing_s, low_pass_hz)");
      }
    }
    return f;
  }

  void readAr(const toml::table& t, const std::string& axis, processing::ArComponent& ar) const {
    const std::string where = axis + ".ar.";
    const toml::key* phi_key = nullptr;
    for (auto&& [key, node] : t) {
      const std::string k(key.str());
      if (k == "phi") {
        phi_key = &key;
        if (!node.is_array()) fail(key.source(), where + "phi must be an array of numbers, got " + tomlTypeName(node));
        ar.phi.clear();
        for (const toml::node& element : *node.as_array()) {
          if (!element.is_number())
            fail(key.source(), where + "phi must contain numbers only, found " + tomlTypeName(element));
          ar.phi.push_back(*element.value<double>());
        }
      } else if (k == "noise_var") {
        ar.noise_var = nonNegative(node, key, where);
      } else {
        fail(key.source(), "unknown key '" + k + "' in [" + axis + ".ar] (expected phi, noise_var)");
      }
    }
    try {
      processing::validateArComponent(ar, axis + ".");
    } catch (const std::invalid_argument& e) {
      if (phi_key) fail(phi_key->source(), e.what());
      doc_.failFile(e.what());
    }
  }

 private:
  const formats::TomlDocument& doc_;
  // The file's output rate as read() finds it first, for the lines' centres (the readers are
  // const: this is the one thing read() learns before the tables that need it).
  mutable double line_rate_hz_ = processing::SimulationModel{}.rate_hz;
  mutable bool line_rate_given_ = false;
};

// In arrays values are written as %.17g, where -0.0 would be "-0", which TOML reads as the
// integer 0: write 0 so that the file reads back to what it says (found by fuzz_model_toml).
double unsignedZero(double v) { return v == 0.0 ? 0.0 : v; }

void appendKeyValue(std::string& out, const std::string& key, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  std::string text(buf);
  if (text.find_first_of(".eE") == std::string::npos) text += ".0";  // a TOML float
  out += key + " = " + text + "\n";
}

}  // namespace

SensorModel parseSensorModelToml(std::string_view text, const std::string& source_name) {
  try {
    const formats::TomlDocument doc(text, source_name);
    SensorModel model = ModelReader(doc).read(doc.root());
    try {
      processing::validateSimulationModel(model.simulation);  // anything not already tied to a line
    } catch (const std::invalid_argument& e) {
      doc.failFile(e.what());
    }
    return model;
  } catch (const formats::TomlError& e) {
    throw RecordingError(e.what());
  }
}

processing::SimulationModel parseModelToml(std::string_view text, const std::string& source_name) {
  return parseSensorModelToml(text, source_name).simulation;
}

processing::SimulationModel readModelToml(const std::string& path) { return readSensorModelToml(path).simulation; }

SensorModel readSensorModelToml(const std::string& path) {
  return parseSensorModelToml(formats::readInputFile(path, formats::kModelInput), path);
}

namespace {

void appendCalibration(std::string& out, const std::string& axis, const SensorModel& sensor, std::size_t slot) {
  if (const auto& c = sensor.calibration[slot]) {
    out += "\n[" + axis + ".calibration]\n";
    appendKeyValue(out, "bias_std_dps", c->bias_std_dps);
    appendKeyValue(out, "temperature_coefficient_dps_per_c", c->temperature_coefficient_dps_per_c);
    appendKeyValue(out, "temperature_coefficient_std_dps_per_c", c->temperature_coefficient_std_dps_per_c);
    appendKeyValue(out, "temperature_reference_c", c->temperature_reference_c);
    if (c->warm_up_amplitude_dps != 0.0 || c->warm_up_time_constant_s > 0.0) {
      appendKeyValue(out, "warm_up_amplitude_dps", c->warm_up_amplitude_dps);
      appendKeyValue(out, "warm_up_amplitude_std_dps", c->warm_up_amplitude_std_dps);
      appendKeyValue(out, "warm_up_time_constant_s", c->warm_up_time_constant_s);
    }
  }
  if (const auto& k = sensor.kalman[slot]) {
    out += "\n[" + axis + ".kalman]\n";
    appendKeyValue(out, "a", k->a);
    appendKeyValue(out, "q", k->q);
    appendKeyValue(out, "r", k->r);
  }
}

void appendFilter(std::string& out, const FilterModel& f) {
  out += "\n[filter]\nmean_window = " + std::to_string(f.mean_window) + "\n";
  appendKeyValue(out, "mean_threshold_dps", f.mean_threshold_dps);
  out += "still_window_samples = " + std::to_string(f.still.window_samples) + "\n";
  appendKeyValue(out, "still_mean_threshold_sigmas", f.still.mean_threshold_sigmas);
  appendKeyValue(out, "still_difference_false_alarm", f.still.difference_false_alarm);
  appendKeyValue(out, "bias_instability_horizon_s", f.bias_instability_horizon_s);
  appendKeyValue(out, "temperature_smoothing_s", f.temperature_smoothing_s);
  if (f.low_pass_hz) appendKeyValue(out, "low_pass_hz", *f.low_pass_hz);
}

bool hasCalibration(const SensorModel& m) {
  for (std::size_t a = 0; a < processing::kSimulatedAxes; ++a)
    if (m.calibration[a] || m.kalman[a]) return true;
  return m.filter.has_value();
}

// The simulator's model, with the calibration tables of `sensor` when given.
std::string modelText(const processing::SimulationModel& model, const SensorModel* sensor) {
  std::string out = sensor
                        ? "# gyrod sensor model: simulation (docs/simulator.md) and calibration (docs/calibration.md)\n"
                        : "# gyrod simulation model (docs/simulator.md)\n";
  appendKeyValue(out, "rate_hz", model.rate_hz);
  if (model.dlpf_cfg) out += "dlpf = " + std::to_string(*model.dlpf_cfg) + "\n";
  if (model.fs_sel) out += "fs_sel = " + std::to_string(*model.fs_sel) + "\n";
  out += "\n[temperature]\n";
  appendKeyValue(out, "start_c", model.temperature.start_c);
  appendKeyValue(out, "final_c", model.temperature.final_c);
  appendKeyValue(out, "time_constant_s", model.temperature.time_constant_s);
  appendKeyValue(out, "noise_std_c", model.temperature.noise_std_c);
  const char* names[] = {"x", "y", "z"};
  for (std::size_t a = 0; a < processing::kSimulatedAxes; ++a) {
    const processing::AxisNoiseModel& axis = model.axes[a];
    out += std::string("\n[") + names[a] + "]\n";
    for (processing::NoiseTerm t : processing::kAllNoiseTerms)
      appendKeyValue(out, std::string(processing::noiseTermKey(t)), axis.terms.get(t));
    appendKeyValue(out, "bias_dps", axis.bias_dps);
    if (!axis.ar.phi.empty() || axis.ar.noise_var != 0.0) {
      out += std::string("\n[") + names[a] + ".ar]\nphi = [";
      for (std::size_t i = 0; i < axis.ar.phi.size(); ++i) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s%.17g", i ? ", " : "", unsignedZero(axis.ar.phi[i]));
        out += buf;
      }
      out += "]\n";
      appendKeyValue(out, "noise_var", axis.ar.noise_var);
    }
    const processing::AxisExtraEffects& e = axis.extra;
    if (!e.empty()) {
      out += std::string("\n[") + names[a] + ".extra]\n";
      appendKeyValue(out, "temperature_coefficient_dps_per_c", e.temperature_coefficient_dps_per_c);
      appendKeyValue(out, "temperature_reference_c", e.temperature_reference_c);
      appendKeyValue(out, "gauss_markov_tau_s", e.gauss_markov_tau_s);
      appendKeyValue(out, "gauss_markov_sigma_dps", e.gauss_markov_sigma_dps);
      out += "outlier_count = " + std::to_string(e.outlier_count) + "\n";
      appendKeyValue(out, "outlier_amplitude_dps", e.outlier_amplitude_dps);
      char buf[160];
      out += "sinusoids = [";
      for (std::size_t i = 0; i < e.sinusoids.size(); ++i) {
        std::snprintf(buf, sizeof buf, "%s{freq_hz = %.17g, amp_dps = %.17g, phase_rad = %.17g}", i ? ", " : "",
                      unsignedZero(e.sinusoids[i].freq_hz), unsignedZero(e.sinusoids[i].amp_dps),
                      unsignedZero(e.sinusoids[i].phase_rad));
        out += buf;
      }
      out += "]\nbias_steps = [";
      for (std::size_t i = 0; i < e.bias_steps.size(); ++i) {
        std::snprintf(buf, sizeof buf, "%s{time_s = %.17g, size_dps = %.17g}", i ? ", " : "",
                      unsignedZero(e.bias_steps[i].time_s), unsignedZero(e.bias_steps[i].size_dps));
        out += buf;
      }
      out += "]\n";
      if (!e.narrowband_lines.empty()) {
        out += "narrowband_lines = [";
        for (std::size_t i = 0; i < e.narrowband_lines.size(); ++i) {
          std::snprintf(buf, sizeof buf, "%s{centre_hz = %.17g, width_hz = %.17g, rms_dps = %.17g}", i ? ", " : "",
                        unsignedZero(e.narrowband_lines[i].centre_hz), unsignedZero(e.narrowband_lines[i].width_hz),
                        unsignedZero(e.narrowband_lines[i].rms_dps));
          out += buf;
        }
        out += "]\n";
      }
    }
    if (sensor) appendCalibration(out, names[a], *sensor, a);
  }
  if (sensor && sensor->filter) appendFilter(out, *sensor->filter);
  return out;
}

}  // namespace

std::string modelToToml(const processing::SimulationModel& model) { return modelText(model, nullptr); }

std::string sensorModelToToml(const SensorModel& model) {
  return modelText(model.simulation, hasCalibration(model) ? &model : nullptr);
}

}  // namespace gyrod::recording
