#pragma once

// What the tests of [axes.valve_law] (test_config_valve_law.cpp, test_config_valve_predictive.cpp)
// share: the valve law a parsed configuration runs, and a refusal checked for the file, the line,
// the key path and what was expected.

#include <cstddef>
#include <string>
#include <string_view>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "control/laws/pi_cascade_law.hpp"
#include "daemon/config/load_config.hpp"

namespace hsa::daemon::config_test {

// The 1-based line of the first `needle` in `text`.
inline int line_of(std::string_view text, std::string_view needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string_view::npos) << needle;
  int line = 1;
  for (std::size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

inline const control::ValveLawParams& valve_of(const DaemonConfig& c) {
  return dynamic_cast<const control::PiCascadeLaw&>(*c.axes[0].law).cascade().params().valve;
}

// `table` with its line starting `key =` replaced by `line` (dropped when `line` is empty).
inline std::string with_line(std::string_view table, std::string_view key, std::string_view line) {
  std::string t(table);
  const auto at = t.find("\n" + std::string(key) + " = ");
  EXPECT_NE(at, std::string::npos) << key;
  const auto end = t.find('\n', at + 1);
  t.replace(at + 1, end - at - (line.empty() ? 0 : 1), line);
  return t;
}

// The message parse_config refuses `text` with, read as test.toml.
inline std::string error_of(std::string_view text) {
  try {
    (void)parse_config(text, "test.toml");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "parsing did not throw";
  return {};
}

// The file and the line of `line_text` at the start, then axes[0].valve_law.`key`, then what was expected.
inline void expect_refused_config(std::string_view text, std::string_view line_text, std::string_view key,
                                  std::string_view expected) {
  const std::string message = error_of(text);
  EXPECT_THAT(message, ::testing::StartsWith("test.toml:" + std::to_string(line_of(text, line_text)) + ":"))
      << message;
  EXPECT_THAT(message, ::testing::HasSubstr(": axes[0].valve_law." + std::string(key) + ": ")) << message;
  EXPECT_THAT(message, ::testing::HasSubstr(std::string(expected))) << message;
}

}  // namespace hsa::daemon::config_test
