#include "processing/attitude/quaternion.hpp"

#include <algorithm>
#include <cmath>

namespace gyrod::processing::attitude {

Quaternion multiply(const Quaternion& a, const Quaternion& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

Quaternion conjugate(const Quaternion& q) { return {q[0], -q[1], -q[2], -q[3]}; }

Quaternion normalized(const Quaternion& q) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
}

// v' = v + 2w(u × v) + 2u × (u × v), u = (x, y, z): the sandwich product without building it.
Vector3 rotate(const Quaternion& q, const Vector3& v) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double tx = 2.0 * (y * v[2] - z * v[1]);
  const double ty = 2.0 * (z * v[0] - x * v[2]);
  const double tz = 2.0 * (x * v[1] - y * v[0]);
  return {v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)};
}

Vector3 rotateInverse(const Quaternion& q, const Vector3& v) { return rotate(conjugate(q), v); }

Quaternion fromRotationVector(const Vector3& r) {
  const double angle = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  // sin(θ/2)/θ by its series below 1e-6 rad, where the division loses digits.
  const double s = angle > 1e-6 ? std::sin(0.5 * angle) / angle : 0.5 - angle * angle / 48.0;
  return {std::cos(0.5 * angle), s * r[0], s * r[1], s * r[2]};
}

EulerAngles eulerAngles(const Quaternion& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  EulerAngles e;
  e.roll = std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
  e.pitch = std::asin(std::clamp(2.0 * (w * y - z * x), -1.0, 1.0));
  e.heading = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return e;
}

double inclinationAngle(const Quaternion& e) {
  return 2.0 * std::acos(std::min(1.0, std::sqrt(e[0] * e[0] + e[3] * e[3])));
}

double signedHeadingAngle(const Quaternion& e) { return wrapAngle(2.0 * std::atan2(e[3], e[0])); }

double wrapAngle(double a) {
  constexpr double kPi = 3.14159265358979323846;
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

}  // namespace gyrod::processing::attitude
