// The Prometheus exposition text (daemon/hsad/prometheus_text.hpp): HELP and TYPE lines, label
// escaping, exact counters, gauges' special values, histogram series, and refused names.
#include "daemon/hsad/prometheus_text.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>

namespace hsa::daemon {
namespace {

using Type = PrometheusText::Type;

TEST(PrometheusText, AFamilyHasItsHelpAndTypeLinesThenItsSamples) {
  PrometheusText out;
  out.family("hsa_faults_total", Type::counter, "faults latched, by reason");
  out.sample({{"axis", "lift"}, {"reason", "estop"}}, std::uint64_t{3});
  out.family("hsa_running", Type::gauge, "1 while hsad runs");
  out.sample({}, 1.0);
  EXPECT_EQ(out.text(),
            "# HELP hsa_faults_total faults latched, by reason\n"
            "# TYPE hsa_faults_total counter\n"
            "hsa_faults_total{axis=\"lift\",reason=\"estop\"} 3\n"
            "# HELP hsa_running 1 while hsad runs\n"
            "# TYPE hsa_running gauge\n"
            "hsa_running 1\n");
}

TEST(PrometheusText, LabelValuesEscapeBackslashQuoteAndNewline) {
  EXPECT_EQ(PrometheusText::escape_label_value(R"(a\b"c)" "\nd"), R"(a\\b\"c\nd)");
  EXPECT_EQ(PrometheusText::escape_label_value("modbus 10.0.0.2:502 µ"), "modbus 10.0.0.2:502 µ");  // as is
  PrometheusText out;
  out.family("hsa_driver_errors_total", Type::counter, "x");
  out.sample({{"driver", "io\"1\\\n"}}, std::uint64_t{0});
  EXPECT_THAT(out.text(), ::testing::HasSubstr("hsa_driver_errors_total{driver=\"io\\\"1\\\\\\n\"} 0\n"));
}

TEST(PrometheusText, HelpEscapesBackslashAndNewlineButNotQuotes) {
  EXPECT_EQ(PrometheusText::escape_help("a \"b\" \\ c\nd"), "a \"b\" \\\\ c\\nd");
}

TEST(PrometheusText, CountersKeepEveryDigitAndGaugesTheirSpecialValues) {
  PrometheusText out;
  out.family("c_total", Type::counter, "c");
  out.sample({}, std::numeric_limits<std::uint64_t>::max());
  EXPECT_THAT(out.text(), ::testing::EndsWith("c_total 18446744073709551615\n"));
  EXPECT_EQ(PrometheusText::format_double(0.1), "0.1");  // as written, and it reads back exactly
  EXPECT_EQ(PrometheusText::format_double(2.5e-05), "2.5e-05");
  EXPECT_EQ(PrometheusText::format_double(0.1 + 0.2), "0.30000000000000004");  // 17 digits when it takes them
  EXPECT_EQ(PrometheusText::format_double(std::numeric_limits<double>::quiet_NaN()), "NaN");
  EXPECT_EQ(PrometheusText::format_double(std::numeric_limits<double>::infinity()), "+Inf");
  EXPECT_EQ(PrometheusText::format_double(-std::numeric_limits<double>::infinity()), "-Inf");
}

TEST(PrometheusText, HistogramSeriesTakeTheirSuffixes) {
  PrometheusText out;
  out.family("l_seconds", Type::histogram, "l");
  out.sample({{"le", "1e-05"}}, std::uint64_t{4}, "_bucket");
  out.sample({{"le", "+Inf"}}, std::uint64_t{5}, "_bucket");
  out.sample({}, 1.5, "_sum");
  out.sample({}, std::uint64_t{5}, "_count");
  EXPECT_THAT(out.text(), ::testing::HasSubstr("# TYPE l_seconds histogram\nl_seconds_bucket{le=\"1e-05\"} 4\n"
                                               "l_seconds_bucket{le=\"+Inf\"} 5\nl_seconds_sum 1.5\nl_seconds_count 5\n"));
}

TEST(PrometheusText, BadNamesAndMisplacedSamplesAreRefused) {
  PrometheusText out;
  EXPECT_THROW(out.sample({}, 1.0), std::logic_error);  // no family yet
  EXPECT_THROW(out.family("9lives", Type::gauge, "x"), std::invalid_argument);
  EXPECT_THROW(out.family("hsa-faults", Type::gauge, "x"), std::invalid_argument);
  EXPECT_THROW(out.family("", Type::gauge, "x"), std::invalid_argument);
  out.family("ok:name", Type::gauge, "x");  // colons are allowed in metric names
  EXPECT_THROW(out.sample({{"a:b", "v"}}, 1.0), std::invalid_argument);  // not in label names
  EXPECT_THROW(out.sample({{"__name__", "v"}}, 1.0), std::invalid_argument);  // reserved
  EXPECT_THROW(out.sample({}, 1.0, "_bucket"), std::invalid_argument);  // a gauge has no buckets
}

}  // namespace
}  // namespace hsa::daemon
