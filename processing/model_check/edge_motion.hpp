#pragma once
// Motion at the ends of a static recording: the board still settling after it was put down,
// or picked up before the recording stopped (seen on a real MPU6050 record: rates up to 36
// times the noise for half a second, 0.75–1.12 s after the start, with ringing after it). The
// model check's model is for a gyro at rest, and such a burst would otherwise be named
// outliers and leave the Allan band unexplained at short τ; `gyroctl model-check` leaves the
// burst out (and says so) unless told to keep it.
//
// A sample moves when on any axis |x − median| exceeds kEdgeMotionGate times the axis's
// sample-to-sample noise (1.4826·MAD of first differences / √2: robust to the burst itself).
// A burst is at least kEdgeMotionBurst moving samples each within half a second of the
// previous; only bursts that begin within the first (last) tenth of the record, and at most
// 30 s from its end, count. The kept part starts one second after the last moving sample of
// the leading burst and ends one second before the first of the trailing one; isolated spikes
// (outliers) are never a burst. Nothing is cut when that would leave less than half the
// record. Pure: no I/O.
#include <cstddef>
#include <span>
#include <vector>

namespace gyrod::processing {

inline constexpr double kEdgeMotionGate = 6.0;
inline constexpr std::size_t kEdgeMotionBurst = 3;

struct EdgeMotion {
  std::size_t keep_first = 0, keep_end = 0;  // samples [keep_first, keep_end) are kept
  // Per end: moving samples in its burst, and the largest |x − median| / noise there.
  std::size_t moving_at_start = 0, moving_at_end = 0;
  double largest_z_at_start = 0.0, largest_z_at_end = 0.0;
  bool cut(std::size_t samples) const { return keep_first > 0 || keep_end < samples; }
};

// `axes`: the gyro columns, each of the same length n ≥ 1. Throws std::invalid_argument for
// columns of different lengths or a rate that is not finite and > 0.
EdgeMotion findMotionAtEdges(std::span<const std::vector<double>> axes, double rate_hz);

}  // namespace gyrod::processing
