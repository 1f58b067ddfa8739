#pragma once
// The TOML reader of gyrod's files (the configuration, the simulation model): every
// problem is one line "FILE:LINE: cause", at the line of the key or value at fault.
//
// TomlDocument is the parsed file with its name. TomlSection is one table of it with the
// keys it may hold (any other is an error with a "did you mean"), and typed getters whose
// messages name the key: "FILE:LINE: key 'section.key': requirement (got value)".
// Problems are thrown as TomlError; each file's reader turns them into its own error type.
#include <toml++/toml.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::formats {

// A problem with a TOML file, already phrased for the user: "FILE:LINE: cause".
class TomlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Whether a syntax error names the column as well: "FILE:LINE:COLUMN: description".
enum class SyntaxErrorColumn { Omitted, Shown };

class TomlDocument {
 public:
  // Parses `text`; `file` names it in messages. A syntax error throws TomlError.
  TomlDocument(std::string_view text, std::string file, SyntaxErrorColumn column = SyntaxErrorColumn::Omitted);

  const std::string& file() const { return file_; }
  const toml::table& root() const { return root_; }
  // "FILE:LINE: " for a place in the file, "FILE: " when toml++ knows no line for it.
  std::string location(const toml::source_region& where) const;
  [[noreturn]] void fail(const toml::source_region& where, const std::string& cause) const;
  // A problem of the file as a whole: "FILE: cause".
  [[noreturn]] void failFile(const std::string& cause) const;

 private:
  std::string file_;
  toml::table root_;
};

std::string tomlLocation(const std::string& file, const toml::source_region& where);

// Words for a value in messages.
std::string tomlTypeName(const toml::node& n);      // "a string", "an integer", "a float", ...
std::string tomlRendered(const toml::node& n);      // as written: "\"text\"", 3, 0.5, true; "an array"
std::string tomlTypeAndValue(const toml::node& n);  // "string \"text\"", "integer 3", ...
// The shortest decimal form that reads back as the same double.
std::string shortest(double v);
std::string joinedNames(const std::vector<std::string_view>& names, std::string_view separator = ", ");
// "; did you mean 'NAME'?" when `typo` is a close misspelling of one of `valid`, else "".
std::string didYouMean(std::string_view typo, const std::vector<std::string_view>& valid);

class TomlSection {
 public:
  // `name` is the table's dotted name. Throws TomlError for a key not in `keys`.
  TomlSection(const std::string& file, const toml::table& table, std::string name, std::vector<std::string_view> keys);

  const std::string& file() const { return file_; }
  const std::string& name() const { return name_; }
  // "section.key"; the key alone for the top level (an empty name).
  std::string qualified(std::string_view key) const {
    return name_.empty() ? std::string(key) : name_ + "." + std::string(key);
  }
  const toml::node* node(std::string_view key) const { return table_.get(key); }
  bool has(std::string_view key) const { return node(key) != nullptr; }
  std::string location(const toml::source_region& r) const { return tomlLocation(file_, r); }

  // "FILE:LINE: key 'section.key': requirement (got GOT)" at the line of `n`.
  [[noreturn]] void fail(const toml::node& n, std::string_view key, const std::string& requirement,
                         const std::string& got) const;
  // The same for the value of `key` (which must be present), as written.
  [[noreturn]] void failValue(std::string_view key, const std::string& requirement) const;
  // The same with the type of `n` before its value: "(got string \"x\")".
  [[noreturn]] void failType(const toml::node& n, std::string_view key, const std::string& requirement) const;

  // Absent keys give nullopt; a value of the wrong type is an error.
  // A finite number (integers are accepted where a number is asked for).
  std::optional<double> number(std::string_view key) const;
  double numberFrom(const toml::node& n, std::string_view key) const;
  std::optional<std::int64_t> integer(std::string_view key) const;
  std::optional<std::string> string(std::string_view key) const;
  std::optional<bool> boolean(std::string_view key) const;
  // One of `choices`, returned as its index.
  std::optional<std::size_t> choice(std::string_view key, const std::vector<std::string_view>& choices) const;
  // A number, or an array of numbers, each checked by `ok`.
  std::optional<std::vector<double>> numbers(std::string_view key, const std::function<bool(double)>& ok,
                                             const std::string& requirement) const;
  // A sub-table, or an array of sub-tables (e.g. several bursts), each with `keys`.
  std::vector<TomlSection> tables(std::string_view key, const std::vector<std::string_view>& keys) const;

 private:
  const std::string& file_;
  const toml::table& table_;
  std::string name_;
  std::vector<std::string_view> keys_;
};

}  // namespace gyrod::formats
