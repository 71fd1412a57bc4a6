// TableReader: validated reading of one TOML table. Every getter names the file, the full key path,
// its line, the allowed range and the value given when it refuses; finish() refuses unknown keys.
// Errors are InputError (the CLI exits with status 2).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "hilldem/core/vec3.hpp"

namespace hilldem {

// A real interval with open or closed ends, e.g. Range::closed_open(0, 1) = [0, 1).
struct Range {
  double lo, hi;
  bool lo_open = false, hi_open = false;
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range closed_open(double lo, double hi) { return {lo, hi, false, true}; }
  static Range open_closed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range open(double lo, double hi) { return {lo, hi, true, true}; }
  static Range at_least(double lo) { return closed(lo, HUGE_VAL); }
  static Range positive() { return open(0.0, HUGE_VAL); }
  static Range any() { return open(-HUGE_VAL, HUGE_VAL); }
  bool contains(double v) const;
  std::string text() const;  // "[0, 1)", "(0, inf)"
};

class TableReader {
 public:
  TableReader(const toml::table& table, std::string file, std::string path);

  bool has(const std::string& key) const;
  bool is_string(const std::string& key) const;  // present and a string
  // The string at key without marking it as read (nullopt if absent or not a string).
  std::optional<std::string> peek_string(const std::string& key) const {
    const toml::node* n = table_->get(key);
    return n && n->is_string() ? std::optional<std::string>(*n->value<std::string>()) : std::nullopt;
  }
  std::vector<double> reals(const std::string& key, Range range, const char* unit);  // absent: empty
  // Required when no default is given.
  double real(const std::string& key, std::optional<double> def, Range range, const char* unit);
  std::int64_t integer(const std::string& key, std::optional<std::int64_t> def, std::int64_t lo, std::int64_t hi);
  bool boolean(const std::string& key, bool def);
  std::string string(const std::string& key, std::optional<std::string> def);
  std::string choice(const std::string& key, std::optional<std::string> def, std::initializer_list<const char*> allowed);
  Vec3 vec3(const std::string& key, std::optional<Vec3> def, Range range, const char* unit);
  std::vector<std::string> strings(const std::string& key);  // absent: empty
  std::vector<std::int64_t> integers(const std::string& key);  // absent: empty
  std::vector<Vec3> vec3_list(const std::string& key, const char* unit);  // required
  std::optional<TableReader> table(const std::string& key);
  std::vector<TableReader> tables(const std::string& key);  // array of tables; absent: empty

  // Refuse any key that no getter asked for, listing the keys allowed here.
  void finish() const;
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  std::string where(const std::string& key) const;  // "file: key 'a.b' (line 3)"
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

 private:
  const toml::node* node(const std::string& key);
  std::string full(const std::string& key) const;
  const toml::table* table_;
  std::string file_, path_;
  std::set<std::string> asked_;
};

// Parse a TOML document; syntax errors become InputError with file, line and column.
toml::table parse_toml(const std::string& text, const std::string& file);

}  // namespace hilldem
