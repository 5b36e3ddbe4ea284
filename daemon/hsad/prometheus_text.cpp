#include "daemon/hsad/prometheus_text.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace hsa::daemon {
namespace {

bool valid_name(std::string_view name, bool allow_colon) {
  if (name.empty()) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || (allow_colon && c == ':');
    const bool digit = c >= '0' && c <= '9';
    if (!letter && !(digit && i > 0)) return false;
  }
  return true;
}

std::string_view type_name(PrometheusText::Type type) {
  switch (type) {
    case PrometheusText::Type::counter: return "counter";
    case PrometheusText::Type::gauge: return "gauge";
    case PrometheusText::Type::histogram: return "histogram";
  }
  return "untyped";
}

}  // namespace

std::string PrometheusText::escape_label_value(std::string_view value) {
  std::string out;
  out.reserve(value.size());
  for (const char c : value) {
    if (c == '\\') out += "\\\\";
    else if (c == '"') out += "\\\"";
    else if (c == '\n') out += "\\n";
    else out += c;
  }
  return out;
}

std::string PrometheusText::escape_help(std::string_view help) {
  std::string out;
  out.reserve(help.size());
  for (const char c : help) {
    if (c == '\\') out += "\\\\";
    else if (c == '\n') out += "\\n";
    else out += c;
  }
  return out;
}

std::string PrometheusText::format_double(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  // The shortest of 15, 16 or 17 significant digits that reads back as the same double: 0.1 stays
  // "0.1" (a bucket's le reads as written), and every value round-trips.
  char buf[32];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  return buf;
}

void PrometheusText::family(std::string_view name, Type type, std::string_view help) {
  if (!valid_name(name, true)) throw std::invalid_argument("metric name '" + std::string(name) + "' is not valid");
  name_ = name;
  type_ = type;
  text_ += "# HELP ";
  text_ += name;
  text_ += ' ';
  text_ += escape_help(help);
  text_ += "\n# TYPE ";
  text_ += name;
  text_ += ' ';
  text_ += type_name(type);
  text_ += '\n';
}

void PrometheusText::head(const MetricLabels& labels, std::string_view suffix) {
  if (name_.empty()) throw std::logic_error("PrometheusText: a sample before its family");
  const bool histogram_series = suffix == "_bucket" || suffix == "_sum" || suffix == "_count";
  if (!suffix.empty() && !(type_ == Type::histogram && histogram_series)) {
    throw std::invalid_argument("metric " + name_ + ": suffix '" + std::string(suffix) + "' outside a histogram");
  }
  text_ += name_;
  text_ += suffix;
  if (!labels.empty()) {
    text_ += '{';
    bool first = true;
    for (const auto& [label, value] : labels) {
      if (!valid_name(label, false) || label.substr(0, 2) == "__") {
        throw std::invalid_argument("metric " + name_ + ": label name '" + std::string(label) + "' is not valid");
      }
      if (!first) text_ += ',';
      first = false;
      text_ += label;
      text_ += "=\"";
      text_ += escape_label_value(value);
      text_ += '"';
    }
    text_ += '}';
  }
  text_ += ' ';
}

void PrometheusText::sample(const MetricLabels& labels, std::uint64_t value, std::string_view suffix) {
  head(labels, suffix);
  text_ += std::to_string(value);
  text_ += '\n';
}

void PrometheusText::sample(const MetricLabels& labels, double value, std::string_view suffix) {
  head(labels, suffix);
  text_ += format_double(value);
  text_ += '\n';
}

}  // namespace hsa::daemon
