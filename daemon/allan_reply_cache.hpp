#pragma once
// The ALLAN reply line, formatted once and then copied to every client that asks, until the
// daemon invalidates it (gyrod: when a noise refit completes, i.e. about once per
// allan.refit_interval_s). A pipelining client asking thousands of times then costs a
// string copy per request, not a report and its formatting.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "protocol/protocol.hpp"

namespace gyrod::daemon {

class AllanReplyCache {
 public:
  explicit AllanReplyCache(std::function<protocol::AllanReport()> report) : report_(std::move(report)) {}

  // The cached line, built now if there is none (the first request, or the first after
  // invalidate()). An exception from the report or the formatting propagates and leaves no
  // line cached, so the next request tries again.
  const std::string& line() {
    if (!line_) {
      line_ = protocol::allanLine(report_());
      ++builds_;
    }
    return *line_;
  }
  // The next request builds a fresh line.
  void invalidate() { line_.reset(); }
  // Lines built so far (for tests and the log).
  std::uint64_t builds() const { return builds_; }

 private:
  std::function<protocol::AllanReport()> report_;
  std::optional<std::string> line_;
  std::uint64_t builds_ = 0;
};

}  // namespace gyrod::daemon
