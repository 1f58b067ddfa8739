#pragma once
// The gyrod socket protocol (docs/protocol.md is the reference for every field and unit).
// gpsd style: server → client one JSON object per line, each with a "class"; fields that
// have no value are omitted, never null. Client → server one JSON object per line with a
// "cmd". This header is the single place where the wire format is written down in code:
// the server formats with it, gyroctl parses with it (parseServerLine), and the tests read
// what it writes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "processing/allan/allan.hpp"
#include "processing/base/noise_terms.hpp"

namespace gyrod::protocol {

inline constexpr int kProtocolMajor = 1;  // incompatible changes
inline constexpr int kProtocolMinor = 9;  // compatible additions (new classes, new fields)

// A client line longer than this (not counting the '\n' and an optional '\r') is refused
// with an ERROR and the client is disconnected.
inline constexpr std::size_t kMaxRequestLineBytes = 4096;
inline constexpr std::uint32_t kMaxDecimate = 1'000'000;

inline constexpr std::array<std::string_view, 3> kAxisNames = {"x", "y", "z"};
inline constexpr std::array<std::string_view, 3> kStreamNames = {"raw", "mean", "kalman"};

// ---- server → client: per-sample lines (formatted without heap allocation) -------------

// One sample of the three axes after each stage of the chain.
struct RateSample {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t seq = 0;               // sample sequence number, +1 per sample of the device
  double t_s = 0.0;                    // sample time, CLOCK_MONOTONIC [s]
  double temp_c = 0.0;                 // die temperature [°C]
  std::array<double, 3> raw_dps{};     // x, y, z angular rate as read [°/s]
  std::array<double, 3> mean_dps{};    // after the gross-error mean filter [°/s]
  std::array<double, 3> kalman_dps{};  // after the Kalman filter [°/s]
  // Appended by issue 11: the stream to read while the board moves (docs/motion.md).
  // Unset (NaN, so omitted from the line) unless the server fills them.
  std::array<double, 3> rate_dps{kUnset, kUnset, kUnset};  // raw − bias_dps (then the optional low-pass) [°/s]
  std::array<double, 3> bias_dps{kUnset, kUnset, kUnset};  // b̂: the bias subtracted for rate [°/s]
  std::optional<bool> still;                               // the still detector's verdict; none = no detector
  // Appended by issue 12 (protocol 1.3).
  double time_s = kUnset;                                 // wall clock, UTC epoch seconds
  std::array<double, 3> accel_g{kUnset, kUnset, kUnset};  // [g]
  // Appended by issue 32 (protocol 1.9): the orientation from `rate` and `accel`
  // (processing/attitude, docs/attitude.md). Unset unless the server fills them.
  std::array<double, 4> quat{kUnset, kUnset, kUnset, kUnset};            // q_ws: w, x, y, z (Hamilton)
  std::array<double, 3> roll_pitch_heading_deg{kUnset, kUnset, kUnset};  // Z-Y-X Euler angles [°]
  double inclination_std_deg = kUnset;                                   // 1σ of roll and pitch [°]
  double heading_std_deg = kUnset;                                       // 1σ of the heading change [°]
};

// Samples that will never come: seq, seq+1, ..., seq+count−1.
struct GapEvent {
  std::uint64_t first_missing_seq = 0;
  std::uint64_t count = 0;
  // A token, 1..kMaxGapReasonBytes of [a-z0-9_], e.g. "fifo_overflow" (docs/protocol.md).
  std::string_view reason;
};
inline constexpr std::size_t kMaxGapReasonBytes = 48;
// The one gap reason that is not the driver's (driver::gapCauseName): the samples were read
// and recorded, but the daemon's delivery to its clients fell behind and could not keep them.
inline constexpr std::string_view kDeliveryBehindGapReason = "delivery_behind";

// gyrod's MQTT topics, each under the configured prefix: <prefix>/<name> (docs/protocol.md "MQTT").
inline constexpr std::string_view kMqttStatusTopic = "status";
inline constexpr std::string_view kMqttRateTopic = "rate";
inline constexpr std::string_view kMqttGapTopic = "gap";
inline constexpr std::string_view kMqttSummaryTopic = "summary";  // 1 Hz: mean rate, temperature, still
inline constexpr std::string_view kMqttAllanTopic = "allan";      // retained: the ALLAN reply
inline constexpr std::string_view kMqttModelTopic = "model";      // retained: the calibration in use
inline constexpr std::string_view kMqttEffectTopic = "effect";    // each EFFECT line, QoS 1, not retained

// Longest possible RATE line: 32 doubles of ≤ 24 characters in shortest round-trip form
// (768), "time" (≤ 24: fixed with 6 decimals below 1e15, else shortest), a 20-digit seq,
// the keys and punctuation (about 320) and the newline, rounded up.
inline constexpr std::size_t kMaxRateLineBytes = 1280;
// "time" is written with this many decimals: µs resolution (docs/protocol.md).
inline constexpr int kRateTimeDecimals = 6;
inline constexpr std::size_t kMaxGapLineBytes = 160;

// Writes {"class":"RATE",...}\n into `out` and returns its length (newline included).
// Doubles in shortest round-trip form (std::to_chars): parsing them gives back the very
// same double. A field with a non-finite value (a whole array if one element is) is
// omitted, so the line is always valid JSON. Allocates nothing.
std::size_t formatRateLine(const RateSample& sample, std::span<char, kMaxRateLineBytes> out) noexcept;
// {"class":"GAP","seq":..,"count":..,"reason":".."}\n. Throws std::invalid_argument for a
// count of 0 or a reason that is not a token (see GapEvent). Allocates nothing.
std::size_t formatGapLine(const GapEvent& gap, std::span<char, kMaxGapLineBytes> out);

// ---- server → client: replies (may allocate; not on the per-sample path) ------------

std::string versionLine(std::string_view release);
std::string watchLine(bool enable, std::uint32_t decimate);

// What ERROR lines name as the problem ("code" field).
enum class ErrorCode {
  BadRequest,      // the line holds a control byte (NUL, ESC, ...): refused whole, never cut there
  NotJson,         // the line does not parse as JSON
  NotObject,       // JSON, but not an object
  MissingField,    // a required field is absent ("cmd")
  BadType,         // a field has the wrong JSON type
  UnknownCommand,  // "cmd" names no command
  UnknownField,    // a field the command does not take (catches typos)
  DuplicateField,  // a field given twice ({"cmd":"watch","cmd":"status"}): which one was meant?
  OutOfRange,      // a number outside its range (decimate)
  LineTooLong,     // over kMaxRequestLineBytes; the client is then disconnected
  TooManyClients,  // the server is full; the client is then disconnected
  Internal,        // the daemon could not produce the reply
};
std::string_view errorCodeName(ErrorCode code);
std::string errorLine(ErrorCode code, std::string_view message);

// The Allan statistics of the rolling window, one curve per axis and stream.
struct AllanCurve {
  std::vector<double> adev_dps;                 // overlapping Allan deviation at each τ [°/s]; empty: not computed
  std::optional<processing::NoiseTerms> noise;  // fitted IEEE 952 terms (NaN term: not estimated)
  std::optional<processing::NoiseTerms> noise_uncertainty;  // their 1 σ (NaN: not known); with noise
  // The curve as a table (protocol/allan_table.hpp): per τ the deviation, its terms, and,
  // once the noise type is identified, edf and the confidence interval. Empty: not sent.
  std::vector<processing::AllanPoint> points;
};
struct AllanReport {
  double window_s = 0.0;                                         // the configured window (allan.window_s) [s]
  double span_s = std::numeric_limits<double>::quiet_NaN();      // time the samples cover: samples·τ0 [s]
  std::uint64_t samples = 0;                                     // samples in the window now
  double tau0_s = 0.0;                                           // sample period [s]
  double confidence = std::numeric_limits<double>::quiet_NaN();  // two-sided level of the intervals
  std::vector<double> tau_s;                                     // averaging times [s]
  std::array<std::array<AllanCurve, 3>, 3> curves;               // [axis x,y,z][stream raw,mean,kalman]
};
// Throws std::invalid_argument when a computed curve's length differs from tau_s's. A τ at
// which some computed curve is not finite is left out of every list (no nulls).
std::string allanLine(const AllanReport& report);

// One of the driver's counters, by the name STATUS publishes it under.
struct NamedCount {
  std::string name;  // a token, e.g. "fifo_overflows" (docs/protocol.md lists them)
  std::uint64_t value = 0;
  bool operator==(const NamedCount&) const = default;
};

// What the daemon knows about itself (STATUS); empty optionals are omitted.
// The recorder's accounting (STATUS "recorder", while recording). Every record it did not
// write is announced in the recording by a "# DROPPED count=N reason=R" line as soon as a
// write succeeds again.
struct RecorderStatus {
  std::uint64_t written = 0;  // sample and gap lines written to the recording
  std::uint64_t dropped = 0;  // records refused because the recorder's ring was full (ring_full)
  std::uint64_t lost = 0;     // records lost to failed writes (disk_full, write_error)
  std::uint64_t errors = 0;   // failed write, create, sync or close calls
  std::string last_error;     // the last of them with its cause; empty (omitted) when none
  bool operator==(const RecorderStatus&) const = default;
};

// The MQTT publisher's state (STATUS mqtt_*, when [mqtt] url is set).
struct MqttStatus {
  bool connected = false;      // to the broker, now
  std::uint64_t buffered = 0;  // messages kept for the broker now (qos 1)
  std::uint64_t dropped = 0;   // messages the broker will never get from this gyrod
  std::string last_error;      // why the last connection or attempt failed; empty (omitted) when none
  bool operator==(const MqttStatus&) const = default;
};

// gyrod's calibration state (docs/calibration-state.md), with a state directory and a sensor model.
struct CalibrationStateStatus {
  std::string file;          // <state directory>/calibration.toml
  bool restored = false;     // the rate stream started from it
  std::uint64_t writes = 0;  // written since start
  std::string last_error;    // why the last write failed; empty (omitted) when it did not
  bool operator==(const CalibrationStateStatus&) const = default;
};

// The live check (docs/live-check.md), while gyrod runs it.
struct LiveCheckStatus {
  std::uint64_t intervals = 0;       // of still data examined, the baseline's included
  bool baseline_ready = false;       // the baseline is complete: later intervals are compared with it
  std::uint64_t named = 0;           // effects named since start
  std::uint64_t skipped = 0;         // intervals left out because the last examination still ran
  std::vector<std::string> current;  // each effect now named, as its EFFECT line's JSON object
  bool operator==(const LiveCheckStatus&) const = default;
};

// The reply to "effects" (EFFECTS): the effects the live check names now. While gyrod does not
// run the check, `live_check` is false and `reason` says why; the list is then empty.
struct EffectsReport {
  bool live_check = false;           // gyrod runs the live check
  std::string reason;                // why it does not; empty (omitted) while it does
  bool baseline_ready = false;       // with live_check: later intervals are compared with the baseline
  std::uint64_t intervals = 0;       // with live_check: intervals of still data examined
  std::vector<std::string> effects;  // each effect now named, as its EFFECT line's JSON object
  bool operator==(const EffectsReport&) const = default;
};
// The reply from what STATUS says of the live check (none: not running, for `off_reason`).
EffectsReport effectsReportOf(const std::optional<LiveCheckStatus>& live_check, std::string off_reason);
// {"class":"EFFECTS","live_check":"on"|"off",["reason"],["baseline_ready","intervals"],"effects":[...]}
std::string effectsLine(const EffectsReport& report);

// The verdict on the start-up still period (STATUS "still_check", docs/protocol.md).
enum class StillCheck {
  Pending,        // the still period is being collected
  Still,          // it passed: the bias and filter come from a window at rest
  MovedRetrying,  // the board moved: the window was discarded and the still period restarted
  MovedKept,      // it moved at every attempt: the last window was used, its bias is suspect
};
std::string_view stillCheckName(StillCheck check);  // "unknown" for a value not listed

struct StatusReport {
  double uptime_s = 0.0;                          // since the daemon started [s]
  std::uint64_t samples = 0;                      // samples published since start
  std::uint64_t gaps = 0;                         // GAP events since start
  std::uint64_t missing_samples = 0;              // samples lost in those gaps
  std::uint64_t bus_errors = 0;                   // failed bus transfers
  std::uint64_t resets = 0;                       // device resets (FIFO overflow, silent reset, errors)
  std::string device_state;                       // e.g. "streaming" (docs/protocol.md lists them)
  std::string device_reason;                      // why the device is in that state; empty (omitted) while all is well
  std::optional<bool> device_retrying;            // whether the driver keeps trying to reach the device
  std::vector<NamedCount> device_counters;        // every counter of the driver, in its order ("counters")
  std::optional<std::string> device;              // e.g. "/dev/i2c-1@0x68"
  std::optional<double> rate_hz;                  // measured sample rate [Hz]
  std::optional<double> nominal_rate_hz;          // configured sample rate [Hz]
  std::optional<double> temp_c;                   // latest die temperature [°C]
  std::optional<std::string> bias_source;         // where the bias subtracted from raw comes from
  std::optional<std::string> still_check;         // stillCheckName(); none: no still period at start
  std::optional<std::string> still_check_detail;  // what the check found, for a person
  std::optional<std::string> rate_model;          // what the rate stream subtracts: "model FILE" or "bias"
  std::optional<std::string> recording;           // file being recorded to
  std::optional<RecorderStatus> recorder;         // the recorder's counts, while recording
  std::optional<MqttStatus> mqtt;                 // the MQTT publisher, when configured
  std::optional<CalibrationStateStatus> calibration_state;  // with a state directory and a sensor model
  std::optional<LiveCheckStatus> live_check;                // while gyrod runs the live check
};

// What the server knows about its clients; added to every STATUS line.
struct ClientStatus {
  std::uint64_t id = 0;                  // 1, 2, ... in order of connection
  std::optional<std::int64_t> pid, uid;  // of the peer (SO_PEERCRED)
  bool watch = false;
  std::uint32_t decimate = 1;
  std::uint64_t lines_queued = 0;  // lines put into its output buffer
  std::uint64_t lines_sent = 0;    // lines completely written to the socket
  std::size_t buffered_bytes = 0;  // bytes waiting in its output buffer
  bool self = false;               // the client that asked
};
struct ServerStatus {
  std::size_t clients = 0;              // connected now
  std::uint64_t clients_total = 0;      // accepted since start
  std::uint64_t clients_dropped = 0;    // disconnected because their buffer was full
  std::uint64_t lines_dropped = 0;      // lines those clients never received
  std::size_t client_buffer_bytes = 0;  // capacity of each client's output buffer
  std::vector<ClientStatus> client_list;
};
std::string statusLine(const StatusReport& daemon, const ServerStatus& server);

// ---- server → client, read by a client ---------------------------------------------------
// The parse functions read what the functions above write (format → parse gives back the
// same values). A field the formatter leaves out comes back as NaN (numbers), empty
// (strings, lists) or an empty optional; fields and classes this version does not know are
// ignored, as docs/protocol.md asks of clients.

// A server line that is not what this protocol says (not JSON, no "class", a wrong type).
class MalformedLine : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct VersionReply {
  std::string release;
  std::optional<std::int64_t> proto_major, proto_minor;
};
struct WatchReply {
  bool enable = true;
  std::uint32_t decimate = 1;
};
// GapEvent owning its reason.
struct GapNotice {
  std::uint64_t first_missing_seq = 0;
  std::uint64_t count = 0;
  std::string reason;
};
struct ErrorReply {
  std::string code;
  std::optional<std::string> message;
};
// A STATUS field this version does not know (from a newer gyrod), kept for display.
struct OtherField {
  std::string key;
  std::optional<std::string> text;  // when the value is a JSON string
  std::optional<double> real;       // when it is a number with a fraction or exponent
  std::string json;                 // the value as JSON text
};
struct StatusReply {
  StatusReport daemon;
  ServerStatus server;
  std::vector<OtherField> other_fields;  // in the order of the line
};
// A line of a class this version does not know.
struct OtherClass {
  std::string name;
};
using ServerMessage = std::variant<VersionReply, WatchReply, RateSample, GapNotice, AllanReport, StatusReply,
                                   EffectsReport, ErrorReply, OtherClass>;

// Parses one server line (without its '\n'). Throws MalformedLine.
ServerMessage parseServerLine(std::string_view line);

// ---- client → server ------------------------------------------------------------------

struct WatchRequest {
  bool enable = true;
  std::uint32_t decimate = 1;
};
struct AllanRequest {};
struct StatusRequest {};
struct EffectsRequest {};
using Request = std::variant<WatchRequest, AllanRequest, StatusRequest, EffectsRequest>;

// A client line that is not a valid request: what the ERROR line will say.
class ProtocolError : public std::invalid_argument {
 public:
  ProtocolError(ErrorCode code, const std::string& message) : std::invalid_argument(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

// The request as one line, without its '\n' (parseRequest reads it back).
std::string requestLine(const Request& request);

// Parses one line (without its '\n'). Throws ProtocolError saying what is wrong.
Request parseRequest(std::string_view line);

}  // namespace gyrod::protocol
