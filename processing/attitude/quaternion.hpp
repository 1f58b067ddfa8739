#pragma once
// Hamilton quaternions (w, x, y, z) for attitude: q ⊗ p composes rotations (p first), a unit q
// rotates a vector v to q ⊗ (0, v) ⊗ q*, and q_ws (sensor → world) maps sensor-frame vectors into
// the world frame. The world is z up; heading is the rotation about world z.
#include <array>

namespace gyrod::processing::attitude {

using Quaternion = std::array<double, 4>;  // w, x, y, z
using Vector3 = std::array<double, 3>;

inline constexpr Quaternion kIdentityQuaternion{1.0, 0.0, 0.0, 0.0};

Quaternion multiply(const Quaternion& a, const Quaternion& b);
Quaternion conjugate(const Quaternion& q);
Quaternion normalized(const Quaternion& q);
// q ⊗ (0, v) ⊗ q* for a unit q.
Vector3 rotate(const Quaternion& q, const Vector3& v);
// The transpose: q* ⊗ (0, v) ⊗ q.
Vector3 rotateInverse(const Quaternion& q, const Vector3& v);
// exp(rotation_vector / 2): the rotation by |r| radians about r / |r|.
Quaternion fromRotationVector(const Vector3& r);

// Z-Y-X (yaw-pitch-roll) angles of q_ws in radians: q = Rz(heading)·Ry(pitch)·Rx(roll).
struct EulerAngles {
  double roll = 0.0, pitch = 0.0, heading = 0.0;
};
EulerAngles eulerAngles(const Quaternion& q);

// The split of a rotation into a rotation about world z (heading) and the rest (inclination),
// e = e_heading ⊗ e_inclination, as the BROAD benchmark measures errors (Laidig et al. 2021,
// section 4): inclination 2·acos(√(w² + z²)) ∈ [0, π], heading 2·atan2(z, w) wrapped to (−π, π].
double inclinationAngle(const Quaternion& e);
double signedHeadingAngle(const Quaternion& e);
// Wraps an angle in radians to (−π, π].
double wrapAngle(double a);

}  // namespace gyrod::processing::attitude
