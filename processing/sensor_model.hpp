#pragma once
// What the MPU6050 does to the rate before we see it, as math: the on-chip digital
// low-pass filter (DLPF_CFG, register 0x1A), decimation by the sample-rate divider, and
// 16-bit quantisation with saturation. Used by the noise simulator and by the mock
// device in driver/. Values from the MPU-6000/6050 Register Map rev 4.2, §4.3.
#include <complex>
#include <cstdint>

namespace gyrod::processing {

struct DlpfSetting {
  int cfg = 0;                   // DLPF_CFG 0..6
  double bandwidth_hz = 0.0;     // documented gyro bandwidth (−3 dB)
  double delay_ms = 0.0;         // documented gyro delay
  double internal_rate_hz = 0.0; // gyro output rate before SMPLRT_DIV: 8 kHz for cfg 0, else 1 kHz
};
// Throws std::invalid_argument for cfg outside 0..6 (7 is reserved).
const DlpfSetting& dlpfSetting(int cfg);

// A digital low-pass running at the setting's internal rate whose −3 dB point is the
// documented bandwidth. The exact on-chip design is not published; the model chosen and
// why is documented in docs/simulator.md. update() allocates nothing.
class DigitalLowPassFilter {
 public:
  explicit DigitalLowPassFilter(int cfg);
  double update(double x);  // one input at the internal rate → one output
  void reset(double value = 0.0);  // steady state at `value`
  // H(e^{j2πf/fs}) of the filter as implemented (fs = internal rate).
  std::complex<double> frequencyResponse(double f_hz) const;
  const DlpfSetting& setting() const { return *setting_; }

 private:
  const DlpfSetting* setting_;
  // coefficients and state of the chosen design (the implementer's to choose)
  double b0_ = 1, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0;
  double x1_ = 0, x2_ = 0, y1_ = 0, y2_ = 0;
};

// Round to nearest LSB and saturate to [−32768, 32767]. NaN saturates to 0.
std::int16_t quantizeToInt16(double value, double lsb_per_unit);

}  // namespace gyrod::processing
