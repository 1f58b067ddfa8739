// Sampling and power: each internal tick through the DLPF, each sample quantised into the
// output registers and the FIFO, the tick train started and stopped with the power state,
// and the chip's reset.
#include <array>
#include <cmath>

#include "driver/mock/mock_mpu6050.hpp"

namespace gyrod::driver {
namespace {

using mpu6050::Register;
namespace reg = mpu6050;

}  // namespace

double MockMpu6050::internalTickRateHz() const {
  return mpu6050::gyroOutputRateHz(regs_.dlpfCfg()) * (1.0 + config_.clock_error_ppm * 1e-6);
}

void MockMpu6050::internalTick(std::int64_t t_ns) {
  ++counters_.internal_ticks;
  if (rate_mismatch_) ++counters_.source_rate_mismatch_ticks;
  const AnalogSample in = source_.nextTick(static_cast<double>(t_ns - epoch_ns_) * 1e-9);
  if (dlpf_bypass_) {
    filtered_dps_ = in.rate_dps;
  } else {
    if (prime_filters_) {
      // Start each filter in steady state at the first input after waking, instead of
      // from zero (the real start-up transient is not modelled).
      for (int i = 0; i < 3; ++i) filters_[i].reset(in.rate_dps[i]);
    }
    for (int i = 0; i < 3; ++i) filtered_dps_[i] = filters_[i].update(in.rate_dps[i]);
  }
  prime_filters_ = false;
  temperature_c_ = in.temperature_c;
  const bool source_knows_accel =
      std::isfinite(in.accel_g[0]) && std::isfinite(in.accel_g[1]) && std::isfinite(in.accel_g[2]);
  true_accel_g_ = source_knows_accel ? in.accel_g : config_.accel_g;
  // Sample rate = gyro output rate / (1 + SMPLRT_DIV) (RM §4.2 p.11).
  if (ticks_.countTowardsSample(regs_.sampleRateDivider())) sampleTick(t_ns);
}

void MockMpu6050::sampleTick(std::int64_t t_ns) {
  SampleRecord s;
  s.sequence = counters_.samples_produced++;
  s.time_ns = t_ns;
  const int fs_sel = regs_.fsSel();
  const int afs_sel = regs_.afsSel();
  for (int i = 0; i < 3; ++i) {
    s.gyro[i] = processing::quantizeToInt16(filtered_dps_[i], mpu6050::kGyroLsbPerDps[fs_sel]);
    // quantizeToInt16 saturates at ±32767/−32768 LSB, i.e. at the AFS_SEL range, as the chip does.
    s.accel[i] = processing::quantizeToInt16(true_accel_g_[i] + config_.accel_bias_g[i] + accelNoise(),
                                             mpu6050::kAccelLsbPerG[afs_sel]);
  }
  // A glitch due: one bit of one word flipped as the chip writes it (one per sample; several due
  // at once take the samples that follow).
  if (next_glitch_ < glitches_.size() && glitches_[next_glitch_].at_ns <= t_ns - epoch_ns_) {
    const Glitch& g = glitches_[next_glitch_++];
    s.gyro[g.axis] = static_cast<std::int16_t>(static_cast<std::uint16_t>(s.gyro[g.axis]) ^ (1U << g.bit));
    ++counters_.glitched_samples;
  }
  // TEMP_OUT = (T − 36.53) · 340, the inverse of RM Registers 65–66.
  s.temperature =
      processing::quantizeToInt16(temperature_c_ - mpu6050::kTemperatureOffsetDegC, mpu6050::kTemperatureLsbPerDegC);
  latchOutputs(s);

  if (regs_.has(Register::USER_CTRL, reg::USER_CTRL_BIT::FIFO_EN)) {
    std::array<std::uint8_t, 14> frame{};
    const std::size_t n = buildFrame(frame.data());
    if (n > 0) {
      pushFifo(frame.data(), n, t_ns);
      ++counters_.fifo_frames_written;
      s.written_to_fifo = true;
    }
  }
  raiseInterrupt(reg::DATA_RDY_INT, reg::DATA_RDY_EN, t_ns);
  last_sample_ = s;
  if (observer_) observer_(s);
}

void MockMpu6050::latchOutputs(const SampleRecord& s) {
  const auto at = [](Register r, int word) { return static_cast<std::uint8_t>(mpu6050::address(r) + 2 * word); };
  for (int i = 0; i < 3; ++i) {
    regs_.putBigEndian(at(Register::ACCEL_XOUT_H, i), s.accel[i]);
    regs_.putBigEndian(at(Register::GYRO_XOUT_H, i), s.gyro[i]);
  }
  regs_.putBigEndian(at(Register::TEMP_OUT_H, 0), s.temperature);
}

double MockMpu6050::accelNoise() {
  if (config_.accel_noise_g == 0.0) return 0.0;
  return accel_noise_.next() * config_.accel_noise_g;
}

void MockMpu6050::resetChip() {
  regs_.powerOnReset();
  fifo_.powerOnReset();
  reset_busy_ = false;
  reset_done_ns_ = mock::kNever;
  ticks_.restartSampleCount();
  filtered_dps_ = {};
  applyDlpfConfig(0);
  updateSampling();
  int_line_.powerOnReset(now_ns_);
  recomputeNextEvent();
}

void MockMpu6050::applyDlpfConfig(int cfg) {
  // DLPF_CFG 7 is "reserved" in the register map; PX4 uses it as "bypass DLPF" and the gyro
  // then runs at 8 kHz, so the mock passes the rate through unfiltered.
  dlpf_bypass_ = cfg == mpu6050::kDlpfCfgReserved;
  if (!dlpf_bypass_) {
    for (int i = 0; i < 3; ++i) {
      filters_[i] = processing::DigitalLowPassFilter(cfg);
      filters_[i].reset(filtered_dps_[i]);
    }
  }
  const double expected = source_.expectedTickRateHz();
  rate_mismatch_ = expected > 0.0 && expected != mpu6050::gyroOutputRateHz(cfg);
}

void MockMpu6050::updateSampling() {
  const bool should = powered_ && !reset_busy_ && !regs_.has(Register::PWR_MGMT_1, reg::SLEEP);
  if (should && !ticks_.running()) {
    startSampling(now_ns_);
  } else if (!should && ticks_.running()) {
    ticks_.stop();
  }
}

void MockMpu6050::startSampling(std::int64_t t_ns) {
  ticks_.start(t_ns, 1e9 / internalTickRateHz());
  prime_filters_ = true;
}

}  // namespace gyrod::driver
