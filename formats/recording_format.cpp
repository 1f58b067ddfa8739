#include "formats/recording_format.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <system_error>

#include "formats/recording_csv.hpp"  // kAccelColumns

namespace gyrod::recording {
namespace {

constexpr std::string_view kGapPrefix = "# GAP ";
constexpr std::string_view kDroppedPrefix = "# DROPPED ";

// Appends to a line that has room for it (RecordingLine is sized for the longest line).
class LineWriter {
 public:
  explicit LineWriter(RecordingLine& line) : line_(line), p_(line.bytes.data()) {}
  LineWriter& text(std::string_view s) {
    std::memcpy(p_, s.data(), s.size());
    p_ += s.size();
    return *this;
  }
  LineWriter& character(char c) {
    *p_++ = c;
    return *this;
  }
  // The shortest decimal form that reads back as the same double.
  LineWriter& number(double v) {
    p_ = std::to_chars(p_, end(), v).ptr;
    return *this;
  }
  LineWriter& fixed(double v, int decimals) {
    p_ = std::to_chars(p_, end(), v, std::chars_format::fixed, decimals).ptr;
    return *this;
  }
  LineWriter& number(std::uint64_t v) {
    p_ = std::to_chars(p_, end(), v).ptr;
    return *this;
  }
  bool empty() const { return p_ == line_.bytes.data(); }
  char last() const { return p_[-1]; }
  std::string_view finish() {
    *p_++ = '\n';
    line_.size = static_cast<std::size_t>(p_ - line_.bytes.data());
    return line_.view();
  }

 private:
  char* end() { return line_.bytes.data() + line_.bytes.size(); }
  RecordingLine& line_;
  char* p_;
};

// Splits "key=value" off the front of `rest` (tokens separated by one space).
std::optional<std::string_view> field(std::string_view& rest, std::string_view key) {
  if (rest.substr(0, key.size()) != key || rest.substr(key.size(), 1) != "=") return std::nullopt;
  const auto space = rest.find(' ');
  const auto value =
      rest.substr(key.size() + 1, space == std::string_view::npos ? std::string_view::npos : space - key.size() - 1);
  rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
  if (value.empty()) return std::nullopt;
  return value;
}

template <class T>
std::optional<T> wholeNumber(std::optional<std::string_view> text) {
  if (!text) return std::nullopt;
  T v{};
  const auto [end, ec] = std::from_chars(text->data(), text->data() + text->size(), v);
  if (ec != std::errc() || end != text->data() + text->size()) return std::nullopt;
  return v;
}

bool isReasonToken(std::string_view s) {
  for (char c : s)
    if (reasonCharacter(c) != c) return false;
  return !s.empty();
}

}  // namespace

std::tm utcCalendarTime(std::int64_t unix_seconds) {
  using namespace std::chrono;
  const sys_seconds t{seconds{unix_seconds}};
  const sys_days day = floor<days>(t);
  const year_month_day date{day};
  const hh_mm_ss<seconds> time{t - day};
  std::tm tm{};
  tm.tm_year = static_cast<int>(date.year()) - 1900;
  tm.tm_mon = static_cast<int>(static_cast<unsigned>(date.month())) - 1;
  tm.tm_mday = static_cast<int>(static_cast<unsigned>(date.day()));
  tm.tm_hour = static_cast<int>(time.hours().count());
  tm.tm_min = static_cast<int>(time.minutes().count());
  tm.tm_sec = static_cast<int>(time.seconds().count());
  tm.tm_wday = static_cast<int>(weekday{day}.c_encoding());
  tm.tm_yday = static_cast<int>((day - sys_days{date.year() / January / 1}).count());
  return tm;
}

std::string recordingHeaderComments(std::int64_t opened_unix_seconds, std::string_view previous_file,
                                    const std::vector<std::string>& comments) {
  const std::tm tm = utcCalendarTime(opened_unix_seconds);
  char stamp[32];
  const auto n = std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", &tm);
  std::string header = "# gyrod recording, opened " + std::string(stamp, n) + "\n";
  if (!previous_file.empty()) header += "# continues " + std::string(previous_file) + "\n";
  for (const auto& c : comments) header += "# " + c + "\n";
  return header;
}

std::string columnsLine(const SampleColumns& columns) {
  std::string line(kColumnsLine.substr(0, kColumnsLine.size() - 1));
  const auto add = [&](std::string_view name) { line.append(",").append(name); };
  if (columns.time) add(kTimeColumn);
  if (columns.accel)
    for (const auto name : kAccelColumns) add(name);
  if (columns.rate) {
    for (const auto name : kRateColumns) add(name);
    for (const auto name : kBiasColumns) add(name);
    add(kStillColumn);
  }
  if (columns.attitude)
    for (const auto name : kAttitudeColumns) add(name);
  return line + "\n";
}

std::string_view formatSampleLine(RecordingLine& line, const SampleColumns& columns, const SampleValues& v) {
  LineWriter w(line);
  const bool finite = std::isfinite(v.t_s) && std::isfinite(v.gx_dps) && std::isfinite(v.gy_dps) &&
                      std::isfinite(v.gz_dps) && std::isfinite(v.temp_c);
  if (!finite) w.text("# NONFINITE ");
  for (double x : {v.t_s, v.gx_dps, v.gy_dps, v.gz_dps, v.temp_c}) {
    if (!w.empty() && w.last() != ' ') w.character(',');
    w.number(x);
  }
  // An optional value: empty when the sample does not have it (NaN), never "nan".
  const auto optional = [&](double x) {
    w.character(',');
    if (std::isfinite(x)) w.number(x);
  };
  if (columns.time) {
    w.character(',');
    // As RATE's "time": the double of the epoch seconds, with µs decimals.
    if (v.wall_ns != 0) w.fixed(static_cast<double>(v.wall_ns) * 1e-9, kTimeDecimals);
  }
  if (columns.accel)
    for (double x : v.accel_g) optional(x);
  if (columns.rate) {
    for (double x : v.rate_dps) optional(x);
    for (double x : v.bias_dps) optional(x);
    w.character(',');
    if (v.still >= 0) w.character(v.still ? '1' : '0');
  }
  if (columns.attitude)
    for (double x : v.attitude) optional(x);
  return w.finish();
}

std::string_view formatSampleLine(RecordingLine& line, double t_s, double gx_dps, double gy_dps, double gz_dps,
                                  double temp_c) {
  SampleValues v;
  v.t_s = t_s;
  v.gx_dps = gx_dps;
  v.gy_dps = gy_dps;
  v.gz_dps = gz_dps;
  v.temp_c = temp_c;
  return formatSampleLine(line, SampleColumns{}, v);
}

std::string_view formatGapLine(RecordingLine& line, std::uint64_t seq, double t_s, std::uint64_t count,
                               std::string_view reason) {
  LineWriter w(line);
  w.text(kGapPrefix).text("seq=").number(seq).text(" t=").number(t_s).text(" count=").number(count);
  return w.text(" reason=").text(reason.empty() ? std::string_view("unknown") : reason).finish();
}

std::string_view formatDroppedLine(RecordingLine& line, std::uint64_t count, std::string_view reason) {
  LineWriter w(line);
  return w.text(kDroppedPrefix).text("count=").number(count).text(" reason=").text(reason).finish();
}

char reasonCharacter(char c) {
  const bool plain =
      (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
  return plain ? c : '_';
}

std::optional<LostSamples> parseLostSamplesLine(std::string_view line) {
  LostSamples lost;
  std::string_view rest;
  if (line.substr(0, kGapPrefix.size()) == kGapPrefix) {
    rest = line.substr(kGapPrefix.size());
    const auto seq = wholeNumber<std::uint64_t>(field(rest, "seq"));
    const auto t = wholeNumber<double>(field(rest, "t"));
    if (!seq || !t) return std::nullopt;
    lost.kind = LostSamples::Kind::Gap;
    lost.seq = *seq;
    lost.t_s = *t;
  } else if (line.substr(0, kDroppedPrefix.size()) == kDroppedPrefix) {
    rest = line.substr(kDroppedPrefix.size());
    lost.kind = LostSamples::Kind::Dropped;
  } else {
    return std::nullopt;
  }
  const auto count = wholeNumber<std::uint64_t>(field(rest, "count"));
  const auto reason = field(rest, "reason");
  if (!count || !reason || !isReasonToken(*reason) || !rest.empty()) return std::nullopt;
  lost.count = *count;
  lost.reason = std::string(*reason);
  return lost;
}

}  // namespace gyrod::recording
