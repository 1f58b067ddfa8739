#include "processing/simulation/motion_profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "processing/base/portable_math.hpp"

namespace gyrod::processing {
namespace {

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

[[noreturn]] void fail(const std::string& what, const std::string& rule, double value) {
  throw std::invalid_argument(what + " must be " + rule + ", got " + formatNumber(value));
}
void requireFinite(double v, const std::string& what) {
  if (!std::isfinite(v)) fail(what, "finite", v);
}
void requirePositive(double v, const std::string& what) {
  if (!std::isfinite(v) || !(v > 0.0)) fail(what, "finite and > 0", v);
}
void requireNonNegative(double v, const std::string& what) {
  if (!std::isfinite(v) || v < 0.0) fail(what, "finite and >= 0", v);
}
// A duration may be kForever (but not NaN or negative).
void requireDuration(double v, const std::string& what) {
  if (std::isnan(v) || !(v > 0.0)) fail(what, "> 0 (or forever)", v);
}
void requireAxis(std::size_t axis, const std::string& what) {
  if (axis >= kMotionAxes)
    throw std::invalid_argument(what + ".axis must be 0, 1 or 2 (x, y, z), got " + std::to_string(axis));
}

bool within(double t, double start, double duration) { return t >= start && t - start < duration; }

}  // namespace

double portableSinOfCycles(double cycles) {
  double frac = cycles - std::floor(cycles);  // [0, 1)
  if (frac >= 0.5) frac -= 1.0;               // [−0.5, 0.5)
  double x = 2.0 * std::numbers::pi * frac;   // [−π, π)
  if (x > 0.5 * std::numbers::pi) x = std::numbers::pi - x;
  if (x < -0.5 * std::numbers::pi) x = -std::numbers::pi - x;
  const double u = portable::tan(0.5 * x);
  return 2.0 * u / (1.0 + u * u);
}

MotionProfile MotionProfile::table(std::vector<MotionPoint> points) {
  if (points.empty())
    throw std::invalid_argument("the motion table needs at least one point (t, wx, wy, wz), got none");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string where = "table point " + std::to_string(i) + ": ";
    requireFinite(points[i].t_s, where + "t");
    for (std::size_t a = 0; a < kMotionAxes; ++a) requireFinite(points[i].rate_dps[a], where + "w" + "xyz"[a]);
    if (i > 0 && !(points[i].t_s > points[i - 1].t_s))
      fail(where + "t", "greater than the previous point's " + formatNumber(points[i - 1].t_s), points[i].t_s);
  }
  MotionProfile p;
  p.kind_ = Kind::Table;
  p.points_ = std::move(points);
  return p;
}

MotionProfile MotionProfile::step(std::size_t axis, double time_s, double rate_dps) {
  requireAxis(axis, "step");
  requireFinite(time_s, "step.time_s");
  requireFinite(rate_dps, "step.rate_dps");
  MotionProfile p;
  p.kind_ = Kind::Step;
  p.axis_ = axis;
  p.a_ = time_s;
  p.b_ = rate_dps;
  return p;
}

MotionProfile MotionProfile::sine(std::size_t axis, double frequency_hz, double amplitude_dps, double start_s,
                                  double duration_s) {
  requireAxis(axis, "sine");
  requirePositive(frequency_hz, "sine.frequency_hz");
  requireNonNegative(amplitude_dps, "sine.amplitude_dps");
  requireFinite(start_s, "sine.start_s");
  requireDuration(duration_s, "sine.duration_s");
  MotionProfile p;
  p.kind_ = Kind::Sine;
  p.axis_ = axis;
  p.a_ = frequency_hz;
  p.b_ = amplitude_dps;
  p.c_ = start_s;
  p.d_ = duration_s;
  return p;
}

MotionProfile MotionProfile::constant(std::size_t axis, double rate_dps, double start_s, double duration_s) {
  requireAxis(axis, "constant");
  requireFinite(rate_dps, "constant.rate_dps");
  requireFinite(start_s, "constant.start_s");
  requireDuration(duration_s, "constant.duration_s");
  MotionProfile p;
  p.kind_ = Kind::Constant;
  p.axis_ = axis;
  p.a_ = rate_dps;
  p.c_ = start_s;
  p.d_ = duration_s;
  return p;
}

MotionProfile MotionProfile::turns(std::size_t axis, double count, double rate_dps, double still_s, double start_s) {
  requireAxis(axis, "turns");
  requirePositive(count, "turns.count");
  if (!std::isfinite(rate_dps) || rate_dps == 0.0) fail("turns.rate_dps", "finite and not 0", rate_dps);
  requireNonNegative(still_s, "turns.still_s");
  requireFinite(start_s, "turns.start_s");
  MotionProfile p;
  p.kind_ = Kind::Turns;
  p.axis_ = axis;
  p.a_ = count;
  p.b_ = rate_dps;
  p.c_ = still_s;
  p.d_ = start_s;
  return p;
}

MotionProfile MotionProfile::sum(std::vector<MotionProfile> parts) {
  MotionProfile p;
  p.kind_ = Kind::Sum;
  p.parts_ = std::move(parts);
  return p;
}

MotionProfile MotionProfile::sequence(std::vector<MotionSegment> segments) {
  MotionProfile p;
  p.kind_ = Kind::Sequence;
  double start = 0.0;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::string what = "sequence segment " + std::to_string(i) + ": duration_s";
    requireDuration(segments[i].duration_s, what);
    if (std::isinf(segments[i].duration_s) && i + 1 != segments.size())
      throw std::invalid_argument(what + " is forever, which only the last segment may be");
    p.starts_.push_back(start);
    p.parts_.push_back(std::move(segments[i].profile));
    start += segments[i].duration_s;
  }
  p.starts_.push_back(start);
  return p;
}

double MotionProfile::turnsRateAt(double t) const {
  const double count = a_, rate = b_, still = c_;
  const double local = t - d_;
  if (local < 0.0) return 0.0;
  const double turn_s = 360.0 / std::fabs(rate);
  const double period = still + turn_s;
  const double full_turns = std::floor(count);
  const double cycle = std::floor(local / period);
  if (cycle > full_turns) return 0.0;
  const double this_turn_s = cycle < full_turns ? turn_s : (count - full_turns) * turn_s;
  const double in_cycle = local - cycle * period;
  return in_cycle >= still && in_cycle - still < this_turn_s ? rate : 0.0;
}

AngularRate MotionProfile::rateAt(double t) const {
  AngularRate w{};
  switch (kind_) {
    case Kind::Rest: break;
    case Kind::Table: {
      if (t <= points_.front().t_s) return points_.front().rate_dps;
      if (t >= points_.back().t_s) return points_.back().rate_dps;
      const auto after =
          std::upper_bound(points_.begin(), points_.end(), t, [](double v, const MotionPoint& p) { return v < p.t_s; });
      const MotionPoint& hi = *after;
      const MotionPoint& lo = *(after - 1);
      const double f = (t - lo.t_s) / (hi.t_s - lo.t_s);
      for (std::size_t a = 0; a < kMotionAxes; ++a) w[a] = lo.rate_dps[a] + f * (hi.rate_dps[a] - lo.rate_dps[a]);
      break;
    }
    case Kind::Step:
      if (t >= a_) w[axis_] = b_;
      break;
    case Kind::Sine:
      if (within(t, c_, d_)) w[axis_] = b_ * portableSinOfCycles(a_ * (t - c_));
      break;
    case Kind::Constant:
      if (within(t, c_, d_)) w[axis_] = a_;
      break;
    case Kind::Turns: w[axis_] = turnsRateAt(t); break;
    case Kind::Sum:
      for (const MotionProfile& part : parts_) {
        const AngularRate v = part.rateAt(t);
        for (std::size_t a = 0; a < kMotionAxes; ++a) w[a] += v[a];
      }
      break;
    case Kind::Sequence: {
      if (parts_.empty() || t < 0.0 || t >= starts_.back()) break;
      const auto next = std::upper_bound(starts_.begin(), starts_.end(), t);
      const auto i = static_cast<std::size_t>(next - starts_.begin()) - 1;
      return parts_[i].rateAt(t - starts_[i]);
    }
  }
  return w;
}

double MotionProfile::settledFrom() const {
  switch (kind_) {
    case Kind::Rest: return 0.0;
    case Kind::Table: return points_.back().t_s;
    case Kind::Step: return a_;
    case Kind::Sine:
    case Kind::Constant: return std::isinf(d_) ? (kind_ == Kind::Constant ? c_ : kForever) : c_ + d_;
    case Kind::Turns: {
      const double turn_s = 360.0 / std::fabs(b_), full = std::floor(a_), part = a_ - full;
      return d_ + full * (c_ + turn_s) + (part > 0.0 ? c_ + part * turn_s : 0.0);
    }
    case Kind::Sum: {
      double latest = 0.0;
      for (const MotionProfile& part : parts_) latest = std::max(latest, part.settledFrom());
      return latest;
    }
    case Kind::Sequence: return starts_.empty() ? 0.0 : starts_.back();
  }
  return kForever;
}

void AttitudeIntegrator::step(const AngularRate& rate_dps, double dt_s) {
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  const double wx = rate_dps[0] * kRadPerDeg, wy = rate_dps[1] * kRadPerDeg, wz = rate_dps[2] * kRadPerDeg;
  const double norm = std::sqrt(wx * wx + wy * wy + wz * wz);
  double angle = norm * dt_s;  // rad
  if (!(angle > 0.0)) return;
  // portable::tan takes |x| ≤ 1.2: Exp(θ) is applied in equal sub-steps of θ/4 ≤ 1.
  const double pieces = std::ceil(angle / 4.0);
  angle /= pieces;
  const double u = portable::tan(0.25 * angle);     // tan(θ/4): half-angle formulas for θ/2
  const double c = (1.0 - u * u) / (1.0 + u * u);   // cos(θ/2)
  const double s = 2.0 * u / (1.0 + u * u) / norm;  // sin(θ/2)/|ω|
  const Quaternion d{c, s * wx, s * wy, s * wz};
  for (double i = 0.0; i < pieces; i += 1.0) {
    const Quaternion& q = q_;
    const Quaternion r{
        q[0] * d[0] - q[1] * d[1] - q[2] * d[2] - q[3] * d[3], q[0] * d[1] + q[1] * d[0] + q[2] * d[3] - q[3] * d[2],
        q[0] * d[2] - q[1] * d[3] + q[2] * d[0] + q[3] * d[1], q[0] * d[3] + q[1] * d[2] - q[2] * d[1] + q[3] * d[0]};
    // Renormalised every step so that rounding cannot grow the norm over a long run.
    const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    q_ = {r[0] / n, r[1] / n, r[2] / n, r[3] / n};
  }
}

AttitudeIntegrator::Vector AttitudeIntegrator::gravityInBody() const {
  // The third row of R(q) (= the third column of Rᵀ): Rᵀ·(0, 0, 1).
  const auto [w, x, y, z] = q_;
  return {2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)};
}

}  // namespace gyrod::processing
