// gyroctl fleet's table (tools/gyroctl/fleet_table.*): messages as gyrod publishes them,
// the rows and JSON they give; foreign topics and bad payloads counted, never fatal.
#include "tools/gyroctl/fleet_table.hpp"

#include <gtest/gtest.h>

#include <array>
#include <nlohmann/json.hpp>
#include <span>
#include <string>

#include "protocol/protocol.hpp"

using gyrod::gyroctl::FleetTable;
using nlohmann::json;

namespace {

std::string rateMessage(std::uint64_t seq, double temp_c, bool with_rate) {
  gyrod::protocol::RateSample s;
  s.seq = seq;
  s.t_s = 100.0 + static_cast<double>(seq) * 0.02;
  s.temp_c = temp_c;
  s.raw_dps = {1.25, -0.5, 0.125};
  if (with_rate) {
    s.rate_dps = {0.25, -0.125, 0.0625};
    s.bias_dps = {1.0, -0.375, 0.0625};
    s.still = true;
  }
  std::array<char, gyrod::protocol::kMaxRateLineBytes> buffer{};
  std::size_t n = gyrod::protocol::formatRateLine(s, buffer);
  if (n > 0 && buffer[n - 1] == '\n') --n;
  return std::string(buffer.data(), n);
}

const std::string kOnline =
    R"({"state":"online","device":"mock MPU6050","rate_hz":50,"samples":1200,"gaps":2,"samples_lost":7,"mqtt_dropped":1})";

}  // namespace

TEST(FleetTable, ARowPerBoardFromItsStatusAndItsNewestRateMessage) {
  FleetTable table("gyrod");
  table.take("gyrod/rig-1/status", kOnline, 10.0);
  for (std::uint64_t i = 0; i < 11; ++i) table.take("gyrod/rig-1/rate", rateMessage(i, 31.5, true), 10.0 + 0.1 * i);
  table.take("gyrod/rig-2/status", R"({"state":"offline"})", 10.5);
  ASSERT_EQ(table.boards().size(), 2u);
  const json j = json::parse(table.json(11.0));
  const auto& rig1 = j["boards"][0];
  EXPECT_EQ(rig1["board"], "rig-1");
  EXPECT_EQ(rig1["state"], "online");
  EXPECT_EQ(rig1["device"], "mock MPU6050");
  EXPECT_EQ(rig1["samples"], 1200);
  EXPECT_EQ(rig1["gaps"], 2);
  EXPECT_EQ(rig1["samples_lost"], 7);
  EXPECT_EQ(rig1["mqtt_dropped"], 1);
  EXPECT_EQ(rig1["seq"], 10);
  EXPECT_EQ(rig1["rate_messages"], 11);
  EXPECT_NEAR(rig1["messages_per_s"].get<double>(), 10.0, 1e-9);  // 10 intervals in 1 s
  EXPECT_EQ(rig1["rate"], json::array({0.25, -0.125, 0.0625}));
  EXPECT_EQ(rig1["bias"], json::array({1.0, -0.375, 0.0625}));
  EXPECT_EQ(rig1["temp"], 31.5);
  EXPECT_EQ(rig1["still"], true);
  EXPECT_FALSE(rig1.contains("raw"));
  EXPECT_EQ(j["boards"][1]["board"], "rig-2");
  EXPECT_EQ(j["boards"][1]["state"], "offline");
  const std::string text = table.text(11.0);
  EXPECT_NE(text.find("rig-1"), std::string::npos) << text;
  EXPECT_NE(text.find("+0.250   -0.125   +0.062"), std::string::npos) << text;
  EXPECT_NE(text.find("31.50"), std::string::npos) << text;
}

TEST(FleetTable, TheRawRateUntilGyrodSendsItsRateStream) {
  FleetTable table("gyrod");
  table.take("gyrod/rig-1/rate", rateMessage(3, 30.0, false), 1.0);
  const json row = json::parse(table.json(1.0))["boards"][0];
  EXPECT_EQ(row["raw"], json::array({1.25, -0.5, 0.125}));
  EXPECT_FALSE(row.contains("rate"));
  EXPECT_FALSE(row.contains("bias"));
  EXPECT_EQ(row["state"], "?");  // no status seen yet
}

TEST(FleetTable, AnOnlineBoardThatGoesQuietIsShownSilent) {
  FleetTable table("gyrod");
  table.take("gyrod/rig-1/status", kOnline, 0.0);
  EXPECT_EQ(json::parse(table.json(FleetTable::kSilentAfterSeconds - 1))["boards"][0]["state"], "online");
  EXPECT_EQ(json::parse(table.json(FleetTable::kSilentAfterSeconds + 1))["boards"][0]["state"], "silent");
}

TEST(FleetTable, ForeignTopicsAndBadPayloadsAreCountedNotFatal) {
  FleetTable table("lab/gyrod");
  table.take("gyrod/rig-1/status", kOnline, 0.0);    // another root
  table.take("lab/gyrod/status", kOnline, 0.0);      // no board level
  table.take("lab/gyrod/a/b/status", kOnline, 0.0);  // two levels
  table.take("lab/gyrod/rig-1/allan", "{}", 0.0);    // a kind the table does not show
  EXPECT_EQ(table.ignoredMessages(), 4u);
  table.take("lab/gyrod/rig-1/status", "not json", 0.0);
  table.take("lab/gyrod/rig-1/rate", R"({"class":"RATE"})", 0.0);
  table.take("lab/gyrod/rig-1/rate", R"({"class":"GAP","seq":1,"count":2,"reason":"fifo_overflow"})", 0.0);
  table.take("lab/gyrod/rig-1/gap", R"({"class":"GAP","seq":1,"count":2,"reason":"fifo_overflow"})", 0.0);
  ASSERT_EQ(table.boards().size(), 1u);
  const json row = json::parse(table.json(0.0))["boards"][0];
  EXPECT_EQ(row["malformed"], 3);
  EXPECT_EQ(row["gap_messages"], 1);
  EXPECT_EQ(row["rate_messages"], 0);
  EXPECT_EQ(table.statusFilter(), "lab/gyrod/+/status");
  EXPECT_EQ(table.rateFilter(), "lab/gyrod/+/rate");
}
