// Prometheus's text exposition format (version 0.0.4), as the node exporter's textfile collector
// reads it: for each metric family a "# HELP" and a "# TYPE" line, then its samples, one a line,
//
//   name{label="value",...} value
//
// Label values escape backslash, double quote and line feed (\\, \", \n); HELP text escapes
// backslash and line feed. Values are written exactly: a counter's integer as its digits (no
// exponent, so a count past 2^53 keeps its last digits in the file, if not in Prometheus's
// float64), a gauge's double with the fewest significant digits (15 to 17) that read back as the same double, NaN and ±Inf as "NaN", "+Inf", "-Inf".
//
// Names are the caller's constants; they are checked (letters, digits, '_', ':', not starting with
// a digit; label names without ':' and not starting with "__") and a bad one throws
// std::invalid_argument, because it is a programming error that would make the whole file
// unreadable to the collector, not only that line.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hsa::daemon {

using MetricLabels = std::vector<std::pair<std::string_view, std::string>>;

class PrometheusText {
 public:
  enum class Type { counter, gauge, histogram };

  // Starts a family: its HELP and TYPE lines. A family's samples follow before the next family.
  void family(std::string_view name, Type type, std::string_view help);
  // One sample of the current family; `suffix` is "_bucket", "_sum" or "_count" for a histogram's
  // series, else empty.
  void sample(const MetricLabels& labels, std::uint64_t value, std::string_view suffix = {});
  void sample(const MetricLabels& labels, double value, std::string_view suffix = {});

  [[nodiscard]] const std::string& text() const { return text_; }

  // The escapes, for tests and for one another.
  [[nodiscard]] static std::string escape_label_value(std::string_view value);
  [[nodiscard]] static std::string escape_help(std::string_view help);
  [[nodiscard]] static std::string format_double(double value);

 private:
  void head(const MetricLabels& labels, std::string_view suffix);

  std::string text_;
  std::string name_;  // the current family
  Type type_ = Type::gauge;
};

}  // namespace hsa::daemon
