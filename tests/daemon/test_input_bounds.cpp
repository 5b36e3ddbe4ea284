// The bounds on the configuration text (input_bounds.hpp): input that would crash or exhaust the
// TOML parser is refused with the file and the line, and real configurations pass untouched.
#include "daemon/config/input_bounds.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "drivers/config_error.hpp"
#include "daemon/config/load_config.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;

std::string error_of(const std::string& text) {
  try {
    check_input_bounds(text, "deep.toml");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string repeated(const std::string& part, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += part;
  return out;
}

TEST(InputBounds, ADeepDottedTableHeaderIsRefusedBeforeItReachesTheParser) {
  const std::string text = "lcm_url = \"udpm://239.255.76.67:7667?ttl=0\"\n[a" + repeated(".a", 50'000) + "]\n";
  EXPECT_THAT(error_of(text), HasSubstr("deep.toml:2: a dotted key deeper than 32 levels"));
  // And through the loader, which would otherwise overflow its stack here.
  try {
    (void)parse_config(text, "deep.toml");
    FAIL() << "a 50,000-level header was parsed";
  } catch (const io::ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("deep.toml:2:"));
  }
}

TEST(InputBounds, DeepArraysAndInlineTablesAreRefused) {
  EXPECT_THAT(error_of("x = " + repeated("[", 40) + repeated("]", 40) + "\n"),
              HasSubstr("deep.toml:1: arrays, inline tables or table headers nested deeper than 32"));
  EXPECT_THAT(error_of("\n\nx = " + repeated("{a=", 40) + "1" + repeated("}", 40) + "\n"),
              HasSubstr("deep.toml:3: arrays, inline tables or table headers nested"));
}

TEST(InputBounds, TooLargeATextIsRefused) {
  EXPECT_THAT(error_of(std::string(kMaxConfigBytes + 1, '\n')), HasSubstr("more than the 1048576 hsad reads"));
}

TEST(InputBounds, DotsAndBracketsInStringsCommentsAndNumbersDoNotCount) {
  const std::string dots = repeated(".", 100);
  const std::string brackets = repeated("[{", 100);
  EXPECT_EQ(error_of("a = \"" + dots + brackets + "\"\n"), "");
  EXPECT_EQ(error_of("a = '" + dots + brackets + "'\n"), "");
  EXPECT_EQ(error_of("a = \"\"\"\n" + dots + "\n" + brackets + "\n\"\"\"\n"), "");
  EXPECT_EQ(error_of("a = \"escaped \\\" quote " + dots + "\"\n"), "");
  EXPECT_EQ(error_of("# " + dots + brackets + "\n"), "");
  EXPECT_EQ(error_of("a = [" + repeated("1.5, ", 100) + "]\nb = 1979-05-27T00:32:00.999\n"), "");
  EXPECT_EQ(error_of("[a.b.c]\nx.y.z = 1\n[[d.e]]\n"), "");
}

}  // namespace
}  // namespace hsa::daemon
