#include "hilldem/io/toml_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#include <sstream>

#include "hilldem/core/error.hpp"

namespace hilldem {

namespace {
std::string show(const toml::node& n) {
  std::ostringstream os;
  if (n.is_table()) return "a table";
  if (n.is_array()) {
    os << *n.as_array();
    return os.str();
  }
  if (const auto d = n.value_exact<double>()) {  // shortest form: 0.6, not 0.59999...; 10.0 stays a float
    std::string s = fmt::format("{}", *d);
    if (s.find_first_of(".eEni") == std::string::npos) s += ".0";
    return s;
  }
  n.visit([&](auto&& v) { os << v; });
  return os.str();
}
std::string num(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:g}", v);
}
}  // namespace

bool Range::contains(double v) const {
  if (std::isnan(v)) return false;
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;
}

std::string Range::text() const {
  return std::string(lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
}

TableReader::TableReader(const toml::table& table, std::string file, std::string path)
    : table_(&table), file_(std::move(file)), path_(std::move(path)) {}

std::string TableReader::full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

std::string TableReader::where(const std::string& key) const {
  std::string s = file_ + ": key '" + full(key) + "'";
  const toml::node* n = table_->get(key);
  const auto& src = n ? n->source() : table_->source();
  if (src.begin.line > 0) s += " (line " + std::to_string(src.begin.line) + ")";
  return s;
}

void TableReader::fail(const std::string& key, const std::string& message) const {
  throw InputError(where(key) + ": " + message);
}

bool TableReader::has(const std::string& key) const { return table_->contains(key); }

bool TableReader::is_string(const std::string& key) const {
  const toml::node* n = table_->get(key);
  return n && n->is_string();
}

std::vector<double> TableReader::reals(const std::string& key, Range range, const char* unit) {
  const toml::node* n = node(key);
  std::vector<double> out;
  if (!n) return out;
  const std::string want = fmt::format("an array of numbers in {} {}", range.text(), unit);
  const toml::array* a = n->as_array();
  if (!a) fail(key, "must be " + want + "; got " + show(*n));
  for (const toml::node& e : *a) {
    if (!(e.is_integer() || e.is_floating_point())) fail(key, "must be " + want + "; got " + show(*n));
    out.push_back(*e.value<double>());
    if (!range.contains(out.back())) fail(key, "must be " + want + "; got " + show(*n));
  }
  return out;
}

const toml::node* TableReader::node(const std::string& key) {
  asked_.insert(key);
  return table_->get(key);
}

double TableReader::real(const std::string& key, std::optional<double> def, Range range, const char* unit) {
  const toml::node* n = node(key);
  if (!n) {
    if (!def) fail(key, fmt::format("is required: a number in {} {}", range.text(), unit));
    return *def;
  }
  double v;
  if (auto f = n->value<double>(); f && (n->is_floating_point() || n->is_integer())) v = *f;
  else fail(key, fmt::format("must be a number in {} {}; got {}", range.text(), unit, show(*n)));
  if (!std::isfinite(v)) fail(key, fmt::format("must be a finite number in {} {}; got {}", range.text(), unit, show(*n)));
  if (!range.contains(v)) fail(key, fmt::format("must be in {} {}; got {}", range.text(), unit, show(*n)));
  return v;
}

std::int64_t TableReader::integer(const std::string& key, std::optional<std::int64_t> def, std::int64_t lo,
                                  std::int64_t hi) {
  const toml::node* n = node(key);
  if (!n) {
    if (!def) fail(key, fmt::format("is required: an integer in [{}, {}]", lo, hi));
    return *def;
  }
  if (!n->is_integer()) fail(key, fmt::format("must be an integer in [{}, {}]; got {}", lo, hi, show(*n)));
  const std::int64_t v = *n->value<std::int64_t>();
  if (v < lo || v > hi) fail(key, fmt::format("must be an integer in [{}, {}]; got {}", lo, hi, v));
  return v;
}

bool TableReader::boolean(const std::string& key, bool def) {
  const toml::node* n = node(key);
  if (!n) return def;
  if (!n->is_boolean()) fail(key, "must be true or false; got " + show(*n));
  return *n->value<bool>();
}

std::string TableReader::string(const std::string& key, std::optional<std::string> def) {
  const toml::node* n = node(key);
  if (!n) {
    if (!def) fail(key, "is required: a string");
    return *def;
  }
  if (!n->is_string()) fail(key, "must be a string; got " + show(*n));
  return *n->value<std::string>();
}

std::string TableReader::choice(const std::string& key, std::optional<std::string> def,
                                std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string("\"") + a + "\"";
  if (!has(key) && !def) {
    asked_.insert(key);
    fail(key, "is required: one of " + list);
  }
  const std::string v = string(key, def);
  for (const char* a : allowed)
    if (v == a) return v;
  fail(key, "must be one of " + list + "; got \"" + v + "\"");
}

Vec3 TableReader::vec3(const std::string& key, std::optional<Vec3> def, Range range, const char* unit) {
  const toml::node* n = node(key);
  const std::string want = fmt::format("an array of 3 numbers in {} {}", range.text(), unit);
  if (!n) {
    if (!def) fail(key, "is required: " + want);
    return *def;
  }
  const toml::array* a = n->as_array();
  if (!a || a->size() != 3) fail(key, "must be " + want + "; got " + show(*n));
  Vec3 v;
  for (int d = 0; d < 3; ++d) {
    const toml::node& e = (*a)[d];
    if (!(e.is_integer() || e.is_floating_point())) fail(key, "must be " + want + "; got " + show(*n));
    v[d] = *e.value<double>();
    if (!range.contains(v[d])) fail(key, "must be " + want + "; got " + show(*n));
  }
  return v;
}

std::vector<std::string> TableReader::strings(const std::string& key) {
  const toml::node* n = node(key);
  std::vector<std::string> out;
  if (!n) return out;
  if (n->is_string()) return {*n->value<std::string>()};
  const toml::array* a = n->as_array();
  if (!a) fail(key, "must be a string or an array of strings; got " + show(*n));
  for (const toml::node& e : *a) {
    if (!e.is_string()) fail(key, "must be an array of strings; got " + show(*n));
    out.push_back(*e.value<std::string>());
  }
  return out;
}

std::vector<std::int64_t> TableReader::integers(const std::string& key) {
  const toml::node* n = node(key);
  std::vector<std::int64_t> out;
  if (!n) return out;
  if (n->is_integer()) return {*n->value<std::int64_t>()};
  const toml::array* a = n->as_array();
  if (!a) fail(key, "must be an integer or an array of integers; got " + show(*n));
  for (const toml::node& e : *a) {
    if (!e.is_integer()) fail(key, "must be an array of integers; got " + show(*n));
    out.push_back(*e.value<std::int64_t>());
  }
  return out;
}

std::vector<Vec3> TableReader::vec3_list(const std::string& key, const char* unit) {
  const toml::node* n = node(key);
  const std::string want = std::string("an array of [x, y, z] points ") + unit;
  if (!n) fail(key, "is required: " + want);
  const toml::array* a = n->as_array();
  if (!a) fail(key, "must be " + want + "; got " + show(*n));
  std::vector<Vec3> out;
  for (const toml::node& e : *a) {
    const toml::array* p = e.as_array();
    if (!p || p->size() != 3) fail(key, "must be " + want + "; got " + show(*n));
    Vec3 v;
    for (int d = 0; d < 3; ++d) {
      if (!((*p)[d].is_integer() || (*p)[d].is_floating_point())) fail(key, "must be " + want + "; got " + show(*n));
      v[d] = *(*p)[d].value<double>();
      if (!std::isfinite(v[d])) fail(key, "must hold finite numbers; got " + show(*n));
    }
    out.push_back(v);
  }
  return out;
}

std::optional<TableReader> TableReader::table(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  if (!n->is_table()) fail(key, "must be a table; got " + show(*n));
  return TableReader(*n->as_table(), file_, full(key));
}

std::vector<TableReader> TableReader::tables(const std::string& key) {
  const toml::node* n = node(key);
  std::vector<TableReader> out;
  if (!n) return out;
  const toml::array* a = n->as_array();
  if (!a) fail(key, "must be an array of tables ([[" + full(key) + "]]); got " + show(*n));
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::table* t = (*a)[i].as_table();
    if (!t) fail(key, "must be an array of tables ([[" + full(key) + "]]); got " + show(*n));
    out.emplace_back(*t, file_, full(key) + "[" + std::to_string(i + 1) + "]");
  }
  return out;
}

void TableReader::finish() const {
  for (const auto& [k, v] : *table_) {
    const std::string key(k.str());
    if (asked_.count(key)) continue;
    std::string allowed;
    for (const auto& a : asked_) allowed += (allowed.empty() ? "" : ", ") + a;
    throw InputError(where(key) + ": unknown key; allowed here: " + (allowed.empty() ? "(none)" : allowed));
  }
}

namespace {
// toml++ parses recursively: refuse absurd nesting (arrays, inline tables, dotted keys) before it
// can exhaust the stack. Strings are skipped; the limits are far above any real scenario.
void check_nesting(const std::string& text, const std::string& file) {
  constexpr int kMaxDepth = 64, kMaxDots = 64;
  int depth = 0, dots = 0, line = 1;
  char quote = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      dots = 0;
      if (quote == '"' || quote == '\'') quote = 0;  // single-line strings end here (bad TOML anyway)
      continue;
    }
    if (quote) {
      if (c == '\\' && quote == '"') ++i;
      else if (c == quote) quote = 0;
      continue;
    }
    if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxDepth)
        throw InputError(fmt::format("{}: line {}: arrays or tables nested deeper than {} levels", file, line, kMaxDepth));
    } else if (c == ']' || c == '}') {
      depth = std::max(0, depth - 1);
    } else if (c == '.' && !(i > 0 && std::isdigit(static_cast<unsigned char>(text[i - 1])))) {
      if (++dots > kMaxDots)
        throw InputError(fmt::format("{}: line {}: a dotted key with more than {} parts", file, line, kMaxDots));
    }
  }
}
}  // namespace

toml::table parse_toml(const std::string& text, const std::string& file) {
  check_nesting(text, file);
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    const auto& src = e.source();
    throw InputError(fmt::format("{}: TOML syntax error at line {}, column {}: {}", file, src.begin.line,
                                 src.begin.column, e.description()));
  }
}

}  // namespace hilldem
