// The TOML reader shared by gyrod's configuration and the model file: every problem is
// one line "FILE:LINE: cause" (syntax errors optionally with the column), and a section
// names its key, its requirement and the value found.
#include <gtest/gtest.h>

#include <string>

#include "formats/toml_document.hpp"

using namespace gyrod::formats;

namespace {

template <class F>
std::string errorOf(F f) {
  try {
    f();
  } catch (const TomlError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(TomlDocument, SyntaxErrorsNameFileAndLineAndOptionallyTheColumn) {
  const std::string text = "a = 1\nb = [\n";
  const auto without = errorOf([&] { TomlDocument(text, "f.toml"); });
  EXPECT_EQ(without.rfind("f.toml:2: ", 0), 0u) << without;
  const auto with = errorOf([&] { TomlDocument(text, "f.toml", SyntaxErrorColumn::Shown); });
  EXPECT_EQ(with.rfind("f.toml:2:", 0), 0u) << with;
  EXPECT_NE(with.rfind("f.toml:2: ", 0), 0u) << with;  // a column follows the line
}

TEST(TomlDocument, FailuresPointAtTheLineOfTheKey) {
  const TomlDocument doc("\n\nrate = 3\n", "f.toml");
  const auto* node = doc.root().get("rate");
  ASSERT_NE(node, nullptr);
  EXPECT_EQ(errorOf([&] { doc.fail(node->source(), "too fast"); }), "f.toml:3: too fast");
  EXPECT_EQ(errorOf([&] { doc.failFile("no axes"); }), "f.toml: no axes");
  EXPECT_EQ(tomlTypeName(*node), "an integer");
  EXPECT_EQ(tomlRendered(*node), "3");
  EXPECT_EQ(tomlTypeAndValue(*node), "integer 3");
}

TEST(TomlSection, UnknownKeysAndWrongValuesNameTheKey) {
  const TomlDocument doc("[s]\nspeed = \"fast\"\nlimit = 1.5\nlist = [1, -2]\n", "f.toml");
  const auto& table = *doc.root().get_as<toml::table>("s");
  EXPECT_EQ(errorOf([&] {
              TomlSection(doc.file(), table, "s", {"speed", "limit"});
            }),
            "f.toml:4: unknown key 'list' in [s] (valid keys: speed, limit); did you mean 'limit'?");
  const TomlSection s(doc.file(), table, "s", {"speed", "limit", "list"});
  EXPECT_EQ(errorOf([&] { (void)s.number("speed"); }),
            "f.toml:2: key 's.speed': must be a number (got string \"fast\")");
  EXPECT_EQ(errorOf([&] { (void)s.integer("limit"); }), "f.toml:3: key 's.limit': must be an integer (got float 1.5)");
  EXPECT_EQ(errorOf([&] {
              (void)s.numbers(
                  "list", [](double v) { return v >= 0.0; }, "must be ≥ 0");
            }),
            "f.toml:4: key 's.list': must be ≥ 0 (got -2)");
  EXPECT_EQ(s.number("limit"), 1.5);
  EXPECT_FALSE(s.number("absent"));
  EXPECT_EQ(didYouMean("sped", {"speed", "limit"}), "; did you mean 'speed'?");
  EXPECT_EQ(didYouMean("x", {"speed"}), "");
}
