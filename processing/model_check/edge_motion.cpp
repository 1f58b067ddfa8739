#include "processing/model_check/edge_motion.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gyrod::processing {
namespace {

double medianOfCopy(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The largest z of any axis at each sample.
std::vector<double> motionScores(std::span<const std::vector<double>> axes) {
  const std::size_t n = axes.front().size();
  std::vector<double> z(n, 0.0);
  for (const std::vector<double>& x : axes) {
    if (n < 3) break;
    std::vector<double> diffs(n - 1);
    for (std::size_t i = 1; i < n; ++i) diffs[i - 1] = std::fabs(x[i] - x[i - 1]);
    const double noise = 1.4826 * medianOfCopy(std::move(diffs)) / std::sqrt(2.0);
    if (!(noise > 0.0)) continue;  // a constant (or mostly constant, quantised) axis says nothing
    const double centre = medianOfCopy(x);
    for (std::size_t i = 0; i < n; ++i) z[i] = std::max(z[i], std::fabs(x[i] - centre) / noise);
  }
  return z;
}

struct Burst {
  bool found = false;
  std::size_t first = 0, last = 0, moving = 0;
  double largest_z = 0.0;
};

// The bursts among `moving` (sample indices, ascending) that begin before `limit` (in the
// order given: from the start, or from the end with indices counted backwards); the union of
// those that begin within it.
Burst edgeBurst(const std::vector<std::size_t>& moving, const std::vector<double>& z, std::size_t limit,
                std::size_t link) {
  Burst edge;
  std::size_t i = 0;
  while (i < moving.size() && moving[i] < limit) {
    std::size_t j = i;
    while (j + 1 < moving.size() && moving[j + 1] - moving[j] <= link) ++j;
    if (j - i + 1 >= kEdgeMotionBurst) {
      if (!edge.found) edge.first = moving[i];
      edge.found = true;
      edge.last = moving[j];
      for (std::size_t k = i; k <= j; ++k) edge.largest_z = std::max(edge.largest_z, z[moving[k]]);
      edge.moving += j - i + 1;
    }
    i = j + 1;
  }
  return edge;
}

}  // namespace

EdgeMotion findMotionAtEdges(std::span<const std::vector<double>> axes, double rate_hz) {
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0))
    throw std::invalid_argument("edge motion: rate must be finite and > 0");
  EdgeMotion out;
  if (axes.empty()) return out;
  const std::size_t n = axes.front().size();
  for (const std::vector<double>& x : axes)
    if (x.size() != n)
      throw std::invalid_argument("edge motion: columns of " + std::to_string(n) + " and " + std::to_string(x.size()) +
                                  " samples");
  out.keep_end = n;
  if (n < 16) return out;
  const std::vector<double> z = motionScores(axes);
  const auto second = static_cast<std::size_t>(std::ceil(rate_hz));
  const std::size_t link = std::max<std::size_t>(1, second / 2);
  const std::size_t edge = std::min(n / 10, static_cast<std::size_t>(30.0 * rate_hz));

  std::vector<std::size_t> forward, backward;  // moving samples, from the start and from the end
  for (std::size_t i = 0; i < n; ++i)
    if (z[i] > kEdgeMotionGate) forward.push_back(i);
  for (auto it = forward.rbegin(); it != forward.rend(); ++it) backward.push_back(n - 1 - *it);
  std::vector<double> z_backward(z.rbegin(), z.rend());

  const Burst start = edgeBurst(forward, z, edge, link);
  const Burst end = edgeBurst(backward, z_backward, edge, link);
  std::size_t keep_first = 0, keep_end = n;
  if (start.found) keep_first = std::min(n, start.last + 1 + second);
  if (end.found) keep_end = (n - 1 - end.last) > second ? n - 1 - end.last - second : 0;
  if (keep_end <= keep_first || keep_end - keep_first < n / 2) return out;  // not an edge: the record moves
  out.keep_first = keep_first;
  out.keep_end = keep_end;
  out.moving_at_start = start.moving;
  out.moving_at_end = end.moving;
  out.largest_z_at_start = start.largest_z;
  out.largest_z_at_end = end.largest_z;
  return out;
}

}  // namespace gyrod::processing
