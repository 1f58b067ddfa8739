#pragma once
// What the MPU6050 does to the rate before we see it, as math: the on-chip digital
// low-pass filter (DLPF_CFG, register 0x1A), decimation by the sample-rate divider, and
// 16-bit quantisation with saturation. Used by the noise simulator and by the mock
// device in driver/. Values from the MPU-6000/6050 Register Map rev 4.2: §4.2 SMPLRT_DIV,
// §4.3 CONFIG (DLPF_CFG), §4.4 GYRO_CONFIG (FS_SEL), §4.18 TEMP_OUT, §4.19 GYRO_*OUT.
#include <complex>
#include <cstdint>

namespace gyrod::processing {

struct DlpfSetting {
  int cfg = 0;                    // DLPF_CFG 0..6
  double bandwidth_hz = 0.0;      // documented gyro bandwidth (−3 dB)
  double delay_ms = 0.0;          // documented gyro delay
  double internal_rate_hz = 0.0;  // gyro output rate before SMPLRT_DIV: 8 kHz for cfg 0, else 1 kHz
};
// Throws std::invalid_argument for cfg outside 0..6 (7 is reserved).
const DlpfSetting& dlpfSetting(int cfg);

// A digital low-pass running at the setting's internal rate whose −3 dB point is the
// documented bandwidth. The exact on-chip design is not published; the model chosen is
// two identical first-order sections (a critically damped second-order low-pass), each
// a bilinear transform of K/(s+K) prewarped so that the cascade is exactly −3 dB at the
// documented bandwidth. Why, and how its delay compares with the documented delay, is in
// docs/simulator.md. update() allocates nothing.
class DigitalLowPassFilter {
 public:
  explicit DigitalLowPassFilter(int cfg);
  double update(double x);         // one input at the internal rate → one output
  void reset(double value = 0.0);  // steady state at `value`
  // H(e^{j2πf/fs}) of the filter as implemented (fs = internal rate).
  std::complex<double> frequencyResponse(double f_hz) const;
  // Group delay of the implemented filter at f → 0, in seconds.
  double groupDelayAtDc() const;
  const DlpfSetting& setting() const { return *setting_; }

 private:
  const DlpfSetting* setting_;
  // Direct-form-I biquad: y = b0·x + b1·x1 + b2·x2 − a1·y1 − a2·y2.
  double b0_ = 1, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0;
  double x1_ = 0, x2_ = 0, y1_ = 0, y2_ = 0;
};

// Gyro sensitivity for GYRO_CONFIG FS_SEL 0..3: 131, 65.5, 32.8, 16.4 LSB per °/s
// (full scale ±250, ±500, ±1000, ±2000 °/s). Throws std::invalid_argument otherwise.
double gyroSensitivityLsbPerDps(int fs_sel);

// Temperature in °C = TEMP_OUT / 340 + 36.53 (register map §4.18).
inline constexpr double kTemperatureLsbPerDegC = 340.0;
inline constexpr double kTemperatureOffsetDegC = 36.53;

// Round to nearest LSB (halves away from zero) and saturate to [−32768, 32767]. NaN
// saturates to 0. Throws std::invalid_argument unless lsb_per_unit is finite and > 0.
std::int16_t quantizeToInt16(double value, double lsb_per_unit);

}  // namespace gyrod::processing
