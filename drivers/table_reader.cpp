#include "drivers/table_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "drivers/config_error.hpp"

namespace hsa::io {

namespace {

// How a value looks in a message: strings quoted, containers by kind, the rest as TOML writes it.
std::string show(const toml::node& node) {
  if (const auto* s = node.as_string()) return '"' + s->get() + '"';
  if (node.is_table()) return "a table";
  if (node.is_array()) return "an array";
  if (const auto* f = node.as_floating_point()) {
    // The shortest text that reads back as the same double: 0.03, not 0.029999999999999999.
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, f->get()).ptr;
    return std::string(buffer, end);
  }
  std::ostringstream out;
  node.visit([&](const auto& n) { out << n; });
  return out.str();
}

std::string join(std::span<const std::string_view> words, std::string_view separator) {
  std::string out;
  for (const auto w : words) {
    if (!out.empty()) out += separator;
    out += w;
  }
  return out;
}

// The TOML header of an array of tables at `path`: "frames[0].channels" is written [[frames.channels]].
std::string header_of(std::string_view path) {
  std::string header;
  bool in_index = false;
  for (const char c : path) {
    if (c == '[') in_index = true;
    if (!in_index) header += c;
    if (c == ']') in_index = false;
  }
  return header;
}

}  // namespace

TableReader::TableReader(const toml::table& table, std::string path,
                         std::shared_ptr<const std::string> source, toml::source_position fallback)
    : table_(&table), path_(std::move(path)), source_(std::move(source)), where_(fallback) {
  if (table.source().begin) where_ = table.source().begin;
}

TableReader TableReader::root(const toml::table& table, std::string_view source_name) {
  return TableReader(table, "", std::make_shared<const std::string>(source_name),
                     toml::source_position{1, 1});
}

TableReader TableReader::of(const toml::table& table) {
  const auto& file = table.source().path;
  return TableReader(table, "", file ? file : std::make_shared<const std::string>(),
                     toml::source_position{});
}

TableReader TableReader::child(const toml::table& table, std::string path) const {
  return TableReader(table, std::move(path), source_, where_);
}

std::string TableReader::key_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

toml::source_position TableReader::position_of(const toml::node* node) const {
  if (node != nullptr && node->source().begin) return node->source().begin;
  return where_;
}

void TableReader::throw_at(toml::source_position where, std::string_view key_path,
                           std::string_view message) const {
  // A table built in code rather than parsed from a file has no place to name.
  std::string located;
  if (!source_->empty()) {
    located = *source_ + ":";
    if (where) located += std::to_string(where.line) + ":" + std::to_string(where.column) + ":";
    located += " ";
  }
  throw ConfigError(located + std::string(key_path) + ": " + std::string(message));
}

void TableReader::fail(std::string_view key, std::string_view expected) const {
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    throw_at(where_, key_path(key), "required key is missing, expected " + std::string(expected));
  }
  throw_at(position_of(node), key_path(key),
           "expected " + std::string(expected) + ", got " + show(*node));
}

void TableReader::fail_here(std::string_view message) const {
  throw_at(where_, path_.empty() ? std::string_view("(top level)") : std::string_view(path_),
           message);
}

double TableReader::number(std::string_view key, const NumberRange& range,
                           std::optional<double> fallback) const {
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    if (!fallback) fail(key, range.expected());
    return *fallback;
  }
  double value = 0.0;
  if (const auto* f = node->as_floating_point()) {
    value = f->get();
  } else if (const auto* i = node->as_integer()) {
    value = static_cast<double>(i->get());
  } else {
    fail(key, range.expected());
  }
  if (!range.contains(value)) fail(key, range.expected());
  return value;
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t min, std::int64_t max,
                                  std::optional<std::int64_t> fallback) const {
  const std::string expected =
      max == std::numeric_limits<std::int64_t>::max()
          ? "an integer >= " + std::to_string(min)
          : "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    if (!fallback) fail(key, expected);
    return *fallback;
  }
  const auto* i = node->as_integer();
  if (i == nullptr || i->get() < min || i->get() > max) fail(key, expected);
  return i->get();
}

Duration TableReader::duration(std::string_view key, const NumberRange& range,
                               std::optional<double> fallback_s) const {
  const double seconds = number(key, range, fallback_s);
  const auto d = std::chrono::round<Duration>(std::chrono::duration<double>(seconds));
  if (d < std::chrono::microseconds(1)) fail(key, range.expected() + " of at least 1 µs");
  return d;
}

bool TableReader::boolean(std::string_view key, std::optional<bool> fallback) const {
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    if (!fallback) fail(key, "true or false");
    return *fallback;
  }
  const auto* b = node->as_boolean();
  if (b == nullptr) fail(key, "true or false");
  return b->get();
}

std::string TableReader::string(std::string_view key, std::string_view expected,
                                std::optional<std::string_view> fallback) const {
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    if (!fallback) fail(key, expected);
    return std::string(*fallback);
  }
  const auto* s = node->as_string();
  if (s == nullptr) fail(key, expected);
  return s->get();
}

std::string TableReader::choice(std::string_view key,
                                std::initializer_list<std::string_view> allowed,
                                std::optional<std::string_view> fallback) const {
  std::string expected;
  std::size_t i = 0;
  for (const auto a : allowed) {
    if (i > 0) expected += (i + 1 == allowed.size()) ? " or " : ", ";
    expected += '"' + std::string(a) + '"';
    ++i;
  }
  const std::string value = string(key, expected, fallback);
  if (std::find(allowed.begin(), allowed.end(), value) == allowed.end()) fail(key, expected);
  return value;
}

std::optional<TableReader> TableReader::table(std::string_view key, bool required,
                                              std::string_view expected) const {
  const toml::node* node = table_->get(key);
  if (node == nullptr) {
    if (required) fail(key, expected);
    return std::nullopt;
  }
  const toml::table* t = node->as_table();
  if (t == nullptr) fail(key, expected);
  return child(*t, key_path(key));
}

std::vector<TableReader> TableReader::tables(std::string_view key) const {
  std::vector<TableReader> out;
  const toml::node* node = table_->get(key);
  if (node == nullptr) return out;
  const toml::array* array = node->as_array();
  const std::string expected = "an array of tables ([[" + header_of(key_path(key)) + "]])";
  if (array == nullptr) fail(key, expected);
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = *array->get(i);
    const std::string path = key_path(key) + "[" + std::to_string(i) + "]";
    const toml::table* t = element.as_table();
    if (t == nullptr) {
      throw_at(position_of(&element), path, "expected a table, got " + show(element));
    }
    out.push_back(child(*t, path));
  }
  return out;
}

void TableReader::reject_unknown_keys(std::initializer_list<std::string_view> known) const {
  reject_unknown_keys(std::span<const std::string_view>(known.begin(), known.size()));
}

void TableReader::reject_unknown_keys(std::span<const std::string_view> known) const {
  for (const auto& [key, value] : *table_) {
    if (std::find(known.begin(), known.end(), key.str()) != known.end()) continue;
    const toml::source_position where =
        key.source().begin ? key.source().begin : position_of(&value);
    throw_at(where, key_path(key.str()), "unknown key, expected one of: " + join(known, ", "));
  }
}

toml::table parse_toml(std::string_view text, std::string_view source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    const toml::source_position where = e.source().begin;
    throw ConfigError(std::string(source_name) + ":" + std::to_string(where.line) + ":" +
                      std::to_string(where.column) + ": TOML syntax error: " + std::string(e.description()));
  }
}

}  // namespace hsa::io
