#pragma once
// True angular-rate profiles ω(t) = (wx, wy, wz) in °/s, for the simulator (which adds them to
// the analog rate before the chip's DLPF) and for the tests that score a stream against the
// truth. A profile is a value: built-ins (step, sine, constant rate, turns), a table of points
// interpolated linearly, and the sum or the sequence of other profiles.
//
// rateAt() allocates nothing and is the same bits on every IEEE-754 machine (the sine comes
// from portable::tan, this file is compiled without FMA contraction), so a simulated record
// with motion reproduces from its seed like one without.
// Every factory throws std::invalid_argument naming the parameter and its value when it is
// out of range (non-finite, a frequency ≤ 0, a table out of order, ...).
#include <array>
#include <cstddef>
#include <limits>
#include <vector>

namespace gyrod::processing {

inline constexpr std::size_t kMotionAxes = 3;  // x, y, z
using AngularRate = std::array<double, kMotionAxes>;

struct MotionPoint {
  double t_s = 0.0;
  AngularRate rate_dps{};
};

class MotionProfile;
struct MotionSegment;

class MotionProfile {
 public:
  static constexpr double kForever = std::numeric_limits<double>::infinity();

  MotionProfile() = default;  // at rest: zero at every t

  // Linear interpolation between points in strictly increasing time (at least one point);
  // before the first point and after the last the end values hold.
  static MotionProfile table(std::vector<MotionPoint> points);
  // 0 before time_s, rate_dps on `axis` (0..2) from time_s on.
  static MotionProfile step(std::size_t axis, double time_s, double rate_dps);
  // amplitude·sin(2π·f·(t − start)) on `axis` for start ≤ t < start + duration, 0 elsewhere.
  static MotionProfile sine(std::size_t axis, double frequency_hz, double amplitude_dps, double start_s = 0.0,
                            double duration_s = kForever);
  // rate_dps on `axis` for start ≤ t < start + duration, 0 elsewhere.
  static MotionProfile constant(std::size_t axis, double rate_dps, double start_s = 0.0, double duration_s = kForever);
  // `count` full turns (360° each, a fraction allowed for the last) about `axis` at rate_dps
  // (its sign is the direction), each preceded and the last also followed by still_s at rest,
  // from start_s: still, turn, still, turn, ..., still. The angle turned is 360·count exactly.
  static MotionProfile turns(std::size_t axis, double count, double rate_dps, double still_s, double start_s = 0.0);
  // The sum of the parts at every t.
  static MotionProfile sum(std::vector<MotionProfile> parts);
  // Each segment's profile in turn, on its own clock starting at 0, for its duration_s; after
  // the last segment, 0 (a segment of duration kForever must be the last).
  static MotionProfile sequence(std::vector<MotionSegment> segments);

  AngularRate rateAt(double t_s) const;
  // The time from which the profile stays at its final value (kForever if it never settles,
  // e.g. an endless sine). For a table: its last point.
  double settledFrom() const;
  bool atRest() const { return kind_ == Kind::Rest; }

 private:
  enum class Kind { Rest, Table, Step, Sine, Constant, Turns, Sum, Sequence };
  Kind kind_ = Kind::Rest;
  std::size_t axis_ = 0;
  double a_ = 0.0, b_ = 0.0, c_ = 0.0, d_ = 0.0;  // meaning per kind, see the factories
  std::vector<MotionPoint> points_;
  std::vector<MotionProfile> parts_;
  std::vector<double> starts_;  // Sequence: start time of each part; one more entry = the end
  double turnsRateAt(double t) const;
};

struct MotionSegment {
  MotionProfile profile;
  double duration_s = 0.0;
};

// The board's attitude, integrated from its true body rates, and what gravity makes an ideal
// accelerometer read in it. Convention (Solà, "Quaternion kinematics for the error-state
// Kalman filter", 2017, eqs. 214 and 101): Hamilton quaternion q = q_wb (body → world), local
// rates, q ← q ⊗ Exp(ω·Δt) with ω held over the step (exact for rates constant over it). The
// world is z up; at the start the board is level, body = world, and an accelerometer at rest
// reads the specific force f_b = R(q)ᵀ·(0, 0, +1) g = (0, 0, +1) g. The same bits on every
// IEEE-754 machine (portable::tan, no FMA contraction in this file).
class AttitudeIntegrator {
 public:
  using Quaternion = std::array<double, 4>;  // w, x, y, z
  using Vector = std::array<double, kMotionAxes>;

  AttitudeIntegrator() = default;  // level
  // Turns the board by rate_dps (body axes, °/s) held for dt_s ≥ 0 seconds.
  void step(const AngularRate& rate_dps, double dt_s);
  // f_b of gravity at rest in the body axes, in g (unit length).
  Vector gravityInBody() const;
  const Quaternion& quaternion() const { return q_; }

 private:
  Quaternion q_{1.0, 0.0, 0.0, 0.0};
};

// sin(2π·cycles) from portable::tan, the same bits on every machine: the phase is reduced
// to whole turns, then to [−π/2, π/2], then the half-angle formula 2u/(1 + u²), u = tan(x/2).
double portableSinOfCycles(double cycles);

}  // namespace gyrod::processing
