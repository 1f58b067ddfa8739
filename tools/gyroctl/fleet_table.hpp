#pragma once
// gyroctl fleet's view of the boards: one row per board, built from what gyrod publishes on
// the broker (docs/protocol.md "MQTT"): <root>/<board>/status (retained), .../rate and .../gap.
// Pure: messages in, with the time they arrived; a table or JSON out. No broker here.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace gyrod::gyroctl {

struct FleetBoard {
  std::string state;   // from status: online, offline; "" until a status came
  std::string device;  // from status
  std::optional<double> configured_rate_hz;
  std::optional<std::uint64_t> samples, gaps, samples_lost, mqtt_dropped;  // from status
  // From the newest rate message:
  std::optional<std::uint64_t> seq;
  std::array<double, 3> rate_dps{}, bias_dps{};
  bool has_rate = false, has_bias = false;
  std::optional<double> temp_c;
  std::optional<bool> still;
  // Counted here, from the messages this subscriber received:
  std::uint64_t rate_messages = 0, gap_messages = 0, malformed = 0;
  double first_rate_s = 0.0, last_rate_s = 0.0;  // arrival times of the first and newest rate message
  double last_seen_s = -1.0;                     // any message
};

class FleetTable {
 public:
  // `root`: the topic levels before the board's name ("gyrod" for gyrod's default prefix
  // gyrod/<hostname>).
  explicit FleetTable(std::string root) : root_(std::move(root)) {}

  // The subscriptions that feed the table.
  std::string statusFilter() const { return root_ + "/+/status"; }
  std::string rateFilter() const { return root_ + "/+/rate"; }
  std::string gapFilter() const { return root_ + "/+/gap"; }

  // One message, arrived at `now_s` (any monotonic clock). Topics outside the root, and
  // payloads that do not parse, are counted and otherwise ignored: one bad board never
  // hides the others.
  void take(std::string_view topic, std::string_view payload, double now_s);

  const std::map<std::string, FleetBoard>& boards() const { return boards_; }
  std::uint64_t ignoredMessages() const { return ignored_; }

  // A board is "silent" when nothing came from it for this long: the status is re-sent every
  // 5 s while gyrod is connected.
  static constexpr double kSilentAfterSeconds = 15.0;
  static std::string shownState(const FleetBoard& b, double now_s);

  // The table as text, one row per board (the header first), and as one JSON object
  // {"boards":[{...}, ...]} on one line.
  std::string text(double now_s) const;
  std::string json(double now_s) const;

 private:
  void takeStatus(FleetBoard& b, std::string_view payload);
  void takeRate(FleetBoard& b, std::string_view payload, double now_s);

  std::string root_;
  std::map<std::string, FleetBoard> boards_;
  std::uint64_t ignored_ = 0;
};

}  // namespace gyrod::gyroctl
