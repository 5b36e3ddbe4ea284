#include "drivers/settings.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace hsa::io {

namespace {

// How a node looks in an error message: strings quoted, the rest as TOML writes them.
std::string show(const toml::node& node) {
  std::ostringstream out;
  if (const auto* s = node.as_string()) {
    out << '"' << s->get() << '"';
  } else if (node.is_table()) {
    out << "a table";
  } else if (node.is_array()) {
    out << "an array";
  } else {
    node.visit([&](const auto& n) { out << n; });
  }
  return out.str();
}

}  // namespace

Settings::Settings(const toml::table& table, std::string path)
    : table_(table), path_(std::move(path)) {}

std::string Settings::key_name(std::string_view key) const { return path_ + std::string(key); }

void Settings::fail(std::string_view key, const std::string& expected) const {
  std::string message = "key '" + key_name(key) + "' must be " + expected;
  if (const toml::node* node = table_.get(key)) message += ", got " + show(*node);
  throw SettingsError(message);
}

double Settings::number(std::string_view key, double fallback) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return fallback;
  if (const auto* f = node->as_floating_point(); f != nullptr && std::isfinite(f->get())) return f->get();
  if (const auto* i = node->as_integer()) return static_cast<double>(i->get());
  fail(key, "a finite number");
}

double Settings::positive_number(std::string_view key, double fallback) const {
  const double value = number(key, fallback);
  if (!(value > 0.0) || !std::isfinite(value)) fail(key, "a positive number");
  return value;
}

std::int64_t Settings::integer(std::string_view key, std::int64_t fallback) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return fallback;
  if (const auto* i = node->as_integer()) return i->get();
  fail(key, "an integer");
}

int Settings::integer_in(std::string_view key, std::int64_t fallback, std::int64_t low, std::int64_t high) const {
  const std::int64_t value = integer(key, fallback);
  if (value < low || value > high) {
    fail(key, "an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
  }
  return static_cast<int>(value);
}

Duration Settings::duration(std::string_view key, double fallback_s) const {
  const double value = positive_number(key, fallback_s);
  const auto d = std::chrono::round<Duration>(std::chrono::duration<double>(value));
  if (d < std::chrono::microseconds(1)) fail(key, "a duration of at least 1 µs");
  return d;
}

bool Settings::boolean(std::string_view key, bool fallback) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return fallback;
  if (const auto* b = node->as_boolean()) return b->get();
  fail(key, "true or false");
}

std::string Settings::string(std::string_view key, std::string_view fallback) const {
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::string(fallback);
  if (const auto* s = node->as_string()) return s->get();
  fail(key, "a string");
}

std::string Settings::choice(std::string_view key, std::initializer_list<std::string_view> allowed,
                             std::string_view fallback) const {
  std::string expected;
  std::size_t i = 0;
  for (const auto a : allowed) {
    if (i > 0) expected += (i + 1 == allowed.size()) ? " or " : ", ";
    expected += "\"" + std::string(a) + "\"";
    ++i;
  }
  const toml::node* node = table_.get(key);
  if (node == nullptr) return std::string(fallback);
  const auto* s = node->as_string();
  if (s == nullptr || std::find(allowed.begin(), allowed.end(), s->get()) == allowed.end()) {
    fail(key, expected);
  }
  return s->get();
}

void Settings::reject_unknown_keys(std::initializer_list<std::string_view> known) const {
  for (const auto& [key, value] : table_) {
    if (std::find(known.begin(), known.end(), key.str()) != known.end()) continue;
    std::string list;
    for (const auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    throw SettingsError("unknown key '" + key_name(key.str()) + "' (known keys: " + list + ")");
  }
}

}  // namespace hsa::io
