#include "tools/gyroctl/model_check_edges.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace gyrod::gyroctl {
namespace {

void keepRows(std::vector<double>& v, std::size_t first, std::size_t end) {
  if (v.empty()) return;
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(end), v.end());
  v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first));
}

// Every per-sample column of the recording cut to [first, end); the line bookkeeping follows.
void keepSamples(recording::Recording& rec, std::size_t first, std::size_t end) {
  keepRows(rec.t, first, end);
  for (auto& a : rec.axes) keepRows(a, first, end);
  keepRows(rec.temp, first, end);
  for (auto& a : rec.true_rate) keepRows(a, first, end);
  for (auto& a : rec.accel_g) keepRows(a, first, end);
  keepRows(rec.time, first, end);
  for (auto& a : rec.rate) keepRows(a, first, end);
  for (auto& a : rec.bias) keepRows(a, first, end);
  keepRows(rec.still, first, end);
  if (!rec.line_numbers.empty()) {
    rec.line_numbers.erase(rec.line_numbers.begin() + static_cast<std::ptrdiff_t>(end), rec.line_numbers.end());
    rec.line_numbers.erase(rec.line_numbers.begin(), rec.line_numbers.begin() + static_cast<std::ptrdiff_t>(first));
  }
  std::vector<recording::Recording::LineRun> runs;
  for (std::size_t r = 0; r < rec.line_runs.size(); ++r) {
    const auto& run = rec.line_runs[r];
    const std::size_t run_end = r + 1 < rec.line_runs.size() ? rec.line_runs[r + 1].first_sample : SIZE_MAX;
    if (run_end <= first || run.first_sample >= end) continue;
    const std::size_t from = std::max(run.first_sample, first);
    runs.push_back({from - first, run.first_line + (from - run.first_sample)});
  }
  rec.line_runs = std::move(runs);
  std::vector<recording::LostSamples> lost;
  for (recording::LostSamples l : rec.lost)
    if (l.before_sample > first && l.before_sample < end) {
      l.before_sample -= first;
      lost.push_back(l);
    }
  rec.lost = std::move(lost);
}

}  // namespace

EdgeTrim trimEdgeMotion(LoadedInput& in, bool keep) {
  EdgeTrim trim;
  trim.samples_read = in.recording.size();
  trim.rate_hz = in.rate_hz;
  trim.kept = keep;
  std::vector<std::vector<double>> gyro;
  for (std::size_t idx = 0; idx < in.recording.axes.size(); ++idx)
    if (recording::axisOfColumn(in.recording.axis_names[idx])) gyro.push_back(in.recording.axes[idx]);
  if (gyro.empty()) gyro = in.recording.axes;
  trim.motion = processing::findMotionAtEdges(gyro, in.rate_hz);
  if (!keep && trim.motion.cut(trim.samples_read))
    keepSamples(in.recording, trim.motion.keep_first, trim.motion.keep_end);
  return trim;
}

std::string edgeTrimText(const std::string& file, const EdgeTrim& trim) {
  const processing::EdgeMotion& m = trim.motion;
  if (!m.cut(trim.samples_read)) return "";
  std::string s;
  char buf[256];
  if (m.keep_first > 0) {
    std::snprintf(buf, sizeof buf, "%s: motion at the start (%zu samples beyond %.0f x the noise, up to %.0f x)",
                  file.c_str(), m.moving_at_start, processing::kEdgeMotionGate, m.largest_z_at_start);
    s += buf;
    std::snprintf(buf, sizeof buf, ": the first %.2f s (%zu samples) %s",
                  static_cast<double>(m.keep_first) / trim.rate_hz, m.keep_first,
                  trim.kept ? "kept (--keep-edges)" : "left out");
    s += buf;
  }
  if (m.keep_end < trim.samples_read) {
    if (!s.empty()) s += "\n";
    const std::size_t cut = trim.samples_read - m.keep_end;
    std::snprintf(buf, sizeof buf,
                  "%s: motion at the end (%zu samples beyond %.0f x the noise, up to %.0f x): the last %.2f s (%zu "
                  "samples) %s",
                  file.c_str(), m.moving_at_end, processing::kEdgeMotionGate, m.largest_z_at_end,
                  static_cast<double>(cut) / trim.rate_hz, cut, trim.kept ? "kept (--keep-edges)" : "left out");
    s += buf;
  }
  return s;
}

nlohmann::json edgeTrimJson(const EdgeTrim& trim) {
  const processing::EdgeMotion& m = trim.motion;
  const bool found = m.cut(trim.samples_read);
  return {{"samples_read", trim.samples_read},
          {"motion_found", found},
          {"left_out", found && !trim.kept},
          {"first_kept_sample", m.keep_first},
          {"end_kept_sample", m.keep_end},
          {"start_s_left_out", static_cast<double>(m.keep_first) / trim.rate_hz},
          {"end_s_left_out", static_cast<double>(trim.samples_read - m.keep_end) / trim.rate_hz},
          {"moving_samples_at_start", m.moving_at_start},
          {"moving_samples_at_end", m.moving_at_end},
          {"largest_z_at_start", m.largest_z_at_start},
          {"largest_z_at_end", m.largest_z_at_end}};
}

}  // namespace gyrod::gyroctl
