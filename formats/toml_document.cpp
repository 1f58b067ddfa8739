#include "formats/toml_document.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "formats/edit_distance.hpp"
#include "formats/quoted_value.hpp"

namespace gyrod::formats {

TomlDocument::TomlDocument(std::string_view text, std::string file, SyntaxErrorColumn column) : file_(std::move(file)) {
  try {
    root_ = toml::parse(text, file_);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    std::string at = file_ + ":" + std::to_string(where.line);
    if (column == SyntaxErrorColumn::Shown) at += ":" + std::to_string(where.column);
    throw TomlError(at + ": " + std::string(e.description()));
  }
}

std::string TomlDocument::location(const toml::source_region& where) const { return tomlLocation(file_, where); }

void TomlDocument::fail(const toml::source_region& where, const std::string& cause) const {
  throw TomlError(location(where) + cause);
}

void TomlDocument::failFile(const std::string& cause) const { throw TomlError(file_ + ": " + cause); }

std::string tomlLocation(const std::string& file, const toml::source_region& where) {
  return where.begin.line > 0 ? file + ":" + std::to_string(where.begin.line) + ": " : file + ": ";
}

std::string tomlTypeName(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

std::string tomlRendered(const toml::node& n) {
  if (auto s = n.as_string()) {
    // A short printable value keeps TOML's double quotes; a long or hostile one is shown
    // bounded and escaped (quotedValue), so that a message is one short line a terminal
    // displays as it is.
    std::string quoted = quotedValue(s->get());
    return quoted == "'" + s->get() + "'" ? "\"" + s->get() + "\"" : quoted;
  }
  if (auto i = n.as_integer()) return std::to_string(i->get());
  if (auto f = n.as_floating_point()) return shortest(f->get());
  if (auto b = n.as_boolean()) return b->get() ? "true" : "false";
  if (n.is_array()) return "an array";
  if (n.is_table()) return "a table";
  return "a date/time";
}

std::string tomlTypeAndValue(const toml::node& n) {
  if (n.is_string()) return "string " + tomlRendered(n);
  if (n.is_integer()) return "integer " + tomlRendered(n);
  if (n.is_floating_point()) return "float " + tomlRendered(n);
  if (n.is_boolean()) return "boolean " + tomlRendered(n);
  return tomlRendered(n);
}

std::string shortest(double v) {
  std::array<char, 32> buf{};
  const auto [end, ec] = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  (void)ec;  // 32 characters always hold the shortest round-trip form of a double
  return std::string(buf.data(), end);
}

std::string joinedNames(const std::vector<std::string_view>& names, std::string_view separator) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) s += separator;
    s += names[i];
  }
  return s;
}

std::string didYouMean(std::string_view typo, const std::vector<std::string_view>& valid) {
  std::string_view best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (auto v : valid) {
    const auto d = editDistance(typo, v);
    if (d < best_distance) best_distance = d, best = v;
  }
  // Only close matches: at most 2 edits, and fewer than half the letters.
  if (best_distance <= 2 && best_distance * 2 <= std::max(typo.size(), best.size()))
    return "; did you mean '" + std::string(best) + "'?";
  return {};
}

TomlSection::TomlSection(const std::string& file, const toml::table& table, std::string name,
                         std::vector<std::string_view> keys)
    : file_(file), table_(table), name_(std::move(name)), keys_(std::move(keys)) {
  for (auto&& [key, node] : table_) {
    (void)node;
    if (std::find(keys_.begin(), keys_.end(), key.str()) != keys_.end()) continue;
    std::ostringstream s;
    // quotedValue: a key is text from the file as well ('name' when short and printable).
    s << location(key.source()) << "unknown key " << quotedValue(key.str())
      << (name_.empty() ? std::string(" at the top level") : " in [" + name_ + "]")
      << " (valid keys: " << joinedNames(keys_) << ")" << didYouMean(key.str(), keys_);
    throw TomlError(s.str());
  }
}

void TomlSection::fail(const toml::node& n, std::string_view key, const std::string& requirement,
                       const std::string& got) const {
  throw TomlError(location(n.source()) + "key '" + qualified(key) + "': " + requirement + " (got " + got + ")");
}

void TomlSection::failValue(std::string_view key, const std::string& requirement) const {
  const auto& n = *node(key);
  fail(n, key, requirement, tomlRendered(n));
}

void TomlSection::failType(const toml::node& n, std::string_view key, const std::string& requirement) const {
  fail(n, key, requirement, tomlTypeAndValue(n));
}

std::optional<double> TomlSection::number(std::string_view key) const {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  return numberFrom(*n, key);
}

double TomlSection::numberFrom(const toml::node& n, std::string_view key) const {
  double v = 0.0;
  if (auto i = n.as_integer())
    v = static_cast<double>(i->get());
  else if (auto f = n.as_floating_point())
    v = f->get();
  else
    failType(n, key, "must be a number");
  if (!std::isfinite(v)) fail(n, key, "must be a finite number", tomlRendered(n));
  return v;
}

std::optional<std::int64_t> TomlSection::integer(std::string_view key) const {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto i = n->as_integer()) return i->get();
  failType(*n, key, "must be an integer");
}

std::optional<std::string> TomlSection::string(std::string_view key) const {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto s = n->as_string()) return s->get();
  failType(*n, key, "must be a string");
}

std::optional<bool> TomlSection::boolean(std::string_view key) const {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  if (auto b = n->as_boolean()) return b->get();
  failType(*n, key, "must be true or false");
}

std::optional<std::size_t> TomlSection::choice(std::string_view key,
                                               const std::vector<std::string_view>& choices) const {
  const auto s = string(key);
  if (!s) return std::nullopt;
  const auto it = std::find(choices.begin(), choices.end(), *s);
  if (it == choices.end()) failValue(key, "must be one of " + joinedNames(choices, ", "));
  return static_cast<std::size_t>(it - choices.begin());
}

std::optional<std::vector<double>> TomlSection::numbers(std::string_view key, const std::function<bool(double)>& ok,
                                                        const std::string& requirement) const {
  const auto* n = node(key);
  if (!n) return std::nullopt;
  std::vector<double> values;
  if (auto a = n->as_array()) {
    for (const auto& element : *a) {
      if (!element.is_number()) failType(element, key, requirement);
      values.push_back(numberFrom(element, key));
      if (!ok(values.back())) fail(element, key, requirement, tomlRendered(element));
    }
  } else {
    if (!n->is_number()) failType(*n, key, requirement);
    values.push_back(numberFrom(*n, key));
    if (!ok(values.back())) failValue(key, requirement);
  }
  return values;
}

std::vector<TomlSection> TomlSection::tables(std::string_view key, const std::vector<std::string_view>& keys) const {
  std::vector<TomlSection> out;
  const auto* n = node(key);
  if (!n) return out;
  if (auto t = n->as_table()) {
    out.emplace_back(file_, *t, qualified(key), keys);
  } else if (auto a = n->as_array()) {
    for (const auto& element : *a) {
      if (!element.is_table()) failType(element, key, "must be a table { ... } or an array of them");
      out.emplace_back(file_, *element.as_table(), qualified(key), keys);
    }
  } else {
    failType(*n, key, "must be a table { ... } or an array of them");
  }
  return out;
}

}  // namespace gyrod::formats
