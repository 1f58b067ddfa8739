// The model check on the real MPU6050 records the project ships (tests/data/mpu6050-*), held
// to the figures pinned in tests/data/model-check-real-records.json (written by
// scripts/model-check-real-records.sh --pin, whose table is in docs/model-check.md, "Real
// records"). A change that makes the check worse on real data is seen here: an axis that
// passed (held-out whiteness p ≥ 0.01, ≥ 90 % in band) or fitted (the check's own misfit
// tests) no longer doing so, fewer such axes, the held-out whiteness p down by more than a
// factor 10, the in-band share down by more than one τ in ten, or other effects named; and
// an axis that does not pass must be told where it misses (a misfit, or a marginal fit).
// A change that makes it better fails too, on purpose, until the pin and the table are
// written again.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tools/run_command.hpp"

using gyrod::test::readWholeFile;
using gyrod::test::runGyroctl;
using gyrod::test::ScratchDir;
using nlohmann::json;

namespace {

const std::filesystem::path kRealRecordsDir = std::filesystem::path(GYROD_TEST_DATA_DIR);

// The record as gyroctl model-check reads it: the Arduino records are raw counts that
// gyroctl import converts, and the long record ships gzip-compressed.
std::string checkableRecord(const std::string& record, const ScratchDir& d) {
  const std::string src = (kRealRecordsDir / record).string();
  if (record.size() > 3 && record.ends_with(".gz")) {
    const auto out = d.path() / std::filesystem::path(record).stem();
    const std::string command = "gzip -dc '" + src + "' > '" + out.string() + "'";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return out.string();
  }
  if (record.rfind("mpu6050-arduino-100hz/", 0) != 0) return src;
  const auto out = d.path() / (std::filesystem::path(record).filename().string());
  const auto r = runGyroctl("import '" + src + "' -o '" + out.string() + "'", d.path());
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return out.string();
}

std::vector<std::string> effectNames(const json& axis) {
  std::vector<std::string> names;
  for (const json& e : axis.at("effects")) names.push_back(e.at("effect").get<std::string>());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(ModelCheckRealRecords, NoRecordGetsWorseThanItsPinnedFigures) {
  const json pinned = json::parse(readWholeFile(kRealRecordsDir / "model-check-real-records.json"));
  ScratchDir d;
  std::size_t passing = 0, fitting = 0;
  for (const json& rec : pinned.at("records")) {
    const std::string record = rec.at("record").get<std::string>();
    const auto r = runGyroctl("model-check '" + checkableRecord(record, d) + "' --json", d.path());
    ASSERT_EQ(r.exit_status, 0) << record << ": " << r.err;
    const json got = json::parse(r.out);
    for (const auto& [axis, want] : rec.at("axes").items()) {
      SCOPED_TRACE(record + " " + axis);
      const json& a = got.at("axes").at(axis);
      const json& misfit = a.at("misfit");
      const double p = misfit.at("ljung_box_p_held_out").get<double>();
      const double band = misfit.at("in_band").get<double>();
      const bool passes = p >= 0.01 && band >= 0.9, fits = !misfit.at("fails").get<bool>();
      passing += passes ? 1 : 0;
      fitting += fits ? 1 : 0;
      if (want.at("passes").get<bool>()) {
        EXPECT_TRUE(passes) << "held-out p " << p << ", in band " << band;
      }
      if (want.at("fits").get<bool>()) {
        EXPECT_TRUE(fits) << misfit.dump();
      }
      // An axis that does not pass is told where it misses: as a misfit, or as a marginal fit.
      if (!passes) {
        EXPECT_TRUE(!fits || misfit.at("marginal").get<bool>()) << misfit.dump();
        EXPECT_TRUE(!misfit.at("tau_lo_s").is_null() || !misfit.at("freq_lo_hz").is_null() ||
                    misfit.at("chain_fails").get<bool>())
            << misfit.dump();
      } else {
        EXPECT_FALSE(misfit.at("marginal").get<bool>()) << misfit.dump();
      }
      EXPECT_GE(p, want.at("ljung_box_p_held_out").get<double>() / 10.0);
      EXPECT_GE(band, want.at("in_band").get<double>() - 0.1);
      EXPECT_EQ(effectNames(a), want.at("effects").get<std::vector<std::string>>());
    }
  }
  EXPECT_GE(passing, pinned.at("passing_axes").get<std::size_t>());
  EXPECT_GE(fitting, pinned.at("fitting_axes").get<std::size_t>());
}
