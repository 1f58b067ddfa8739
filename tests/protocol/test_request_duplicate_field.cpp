// A request that names a field twice is refused with duplicate_field, naming the field:
// a JSON parser would silently keep the last "cmd", and the client would get a reply it
// did not ask for.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "protocol/protocol.hpp"

using namespace gyrod::protocol;

namespace {

void expectDuplicate(const char* line, const std::string& field) {
  try {
    parseRequest(line);
    ADD_FAILURE() << line << " was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.code(), ErrorCode::DuplicateField) << line << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find("\"" + field + "\" appears more than once"), std::string::npos)
        << line << ": " << e.what();
  }
}

}  // namespace

TEST(ProtocolRequests, DuplicateCmdIsRefusedNamingTheKey) {
  expectDuplicate(R"({"cmd":"watch","cmd":"status"})", "cmd");
  expectDuplicate(R"({"cmd":"status","cmd":"status"})", "cmd");  // even when both agree
  expectDuplicate(R"({"cmd":"watch","enable":true,"enable":false})", "enable");
  expectDuplicate(R"({"cmd":"watch","decimate":2,"cmd":"allan","decimate":3})", "cmd");
  // The same key spelt with an escape is the same key once decoded.
  expectDuplicate(R"({"cmd":"status","\u0063md":"watch"})", "cmd");
}

TEST(ProtocolRequests, DuplicateFieldHasItsOwnErrorCodeOnTheWire) {
  EXPECT_EQ(errorCodeName(ErrorCode::DuplicateField), "duplicate_field");
  const auto reply =
      nlohmann::json::parse(errorLine(ErrorCode::DuplicateField, "field \"cmd\" appears more than once"));
  EXPECT_EQ(reply["code"], "duplicate_field");
}

TEST(ProtocolRequests, RequestsWithoutRepeatsStillParse) {
  EXPECT_TRUE(std::holds_alternative<StatusRequest>(parseRequest(R"({"cmd":"status"})")));
  const Request w = parseRequest(R"({"cmd":"watch","enable":false,"decimate":4})");
  EXPECT_EQ(std::get<WatchRequest>(w).decimate, 4u);
  // Not JSON stays not_json, not an object stays not_object: the key check comes after.
  EXPECT_THROW(parseRequest(R"({"cmd":"status","cmd")"), ProtocolError);
  try {
    parseRequest(R"([{"cmd":"a"},{"cmd":"b"}])");
    ADD_FAILURE() << "an array was accepted";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.code(), ErrorCode::NotObject) << e.what();
  }
}
