// hsactl capture / scope --live: what hsactl refuses before sending anything (capture_command.hpp):
// a signal a capture file has not, a missing, doubled or non-finite level, --disarm with anything
// else, and a scope line without a file or a trigger.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "tools/hsactl/capture_command.hpp"

namespace hsa::ctl {
namespace {

CaptureOptions when(const char* signal) {
  CaptureOptions o;
  o.signal = signal;
  return o;
}

TEST(CaptureOptions, ACaptureNowNeedsNothing) {
  EXPECT_EQ(capture_options_error({}), "");
  CaptureOptions o;
  o.pre_s = 0.5;
  o.post_s = 0.2;
  EXPECT_EQ(capture_options_error(o), "");
}

TEST(CaptureOptions, AConditionNamesAFilesSignalAndOneFiniteLevel) {
  CaptureOptions o = when("following_error_m");
  o.above = 0.001;
  EXPECT_EQ(capture_options_error(o), "");
  o.repeat = true;
  EXPECT_EQ(capture_options_error(o), "");
  o.below = -0.001;
  EXPECT_EQ(capture_options_error(o), "--when needs one of --above LEVEL or --below LEVEL");
  o = when("following_error_m");
  EXPECT_EQ(capture_options_error(o), "--when needs one of --above LEVEL or --below LEVEL");
  o.below = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(capture_options_error(o), "the level must be a finite number");
  o = when("t");
  o.above = 1.0;
  const std::string why = capture_options_error(o);
  EXPECT_EQ(why.rfind("--when: unknown signal 't': one of seq, tick, skipped, t_ns,", 0), 0u) << why;
}

TEST(CaptureOptions, ALevelOrRepeatWithoutWhenAndDisarmWithMoreAreRefused) {
  CaptureOptions o;
  o.above = 1.0;
  EXPECT_NE(capture_options_error(o), "");
  o = {};
  o.repeat = true;
  EXPECT_NE(capture_options_error(o), "");
  o = {};
  o.disarm = true;
  EXPECT_EQ(capture_options_error(o), "");
  o.pre_s = 0.1;
  EXPECT_EQ(capture_options_error(o), "--disarm takes no other option");
}

TEST(CaptureOptions, AScopeLineNeedsAFileOrALiveTrigger) {
  EXPECT_EQ(scope_command_line_error(false, true, false, {}), "");
  EXPECT_EQ(scope_command_line_error(false, false, false, {}), "scope: give FILE.mat, or --live AXIS");
  EXPECT_NE(scope_command_line_error(false, true, false, when("position_m")), "");
  EXPECT_NE(scope_command_line_error(true, false, false, {}), "");
  EXPECT_EQ(scope_command_line_error(true, false, true, {}), "");
  EXPECT_EQ(scope_command_line_error(true, false, false, when("position_m")), "");
}

}  // namespace
}  // namespace hsa::ctl
