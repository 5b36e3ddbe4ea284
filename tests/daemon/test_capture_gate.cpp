// The operator thread's checks of a CAPTURE command (daemon/hsad/capture_gate.hpp): lengths within
// the axis's ring (the trigger row included), the defaults, a signal of the capture file, a finite
// level; a refusal says why with the bound and leaves the request as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "daemon/hsad/capture_gate.hpp"
#include "daemon/recorder/recorder_signals.hpp"

namespace hsa::daemon {
namespace {

// The default ring: 2 s at 10 kHz, 0.5 s after the trigger.
constexpr CaptureRingShape kRing{.rows = 20'000, .post_rows = 5'000, .rate_hz = 10'000.0};

CaptureRequest now(double pre_s, double post_s) {
  CaptureRequest q;
  q.action = CaptureAction::now;
  q.pre_s = pre_s;
  q.post_s = post_s;
  return q;
}

CaptureRequest condition(const char* signal, double level) {
  CaptureRequest q;
  q.action = CaptureAction::arm;
  std::snprintf(q.signal, sizeof q.signal, "%s", signal);
  q.level = level;
  return q;
}

TEST(CaptureGate, DefaultsAreTheRingsPostRowsAndAllItHoldsBefore) {
  CaptureRequest q = now(-1, -1);
  EXPECT_EQ(capture_gate::resolve(q, kRing), "");
  EXPECT_EQ(q.post_rows, 5'000u);
  EXPECT_EQ(q.pre_rows, 14'999u);  // with the trigger row: the whole ring
}

TEST(CaptureGate, LengthsAreRoundedToRows) {
  CaptureRequest q = now(0.25, 1.0);
  EXPECT_EQ(capture_gate::resolve(q, kRing), "");
  EXPECT_EQ(q.pre_rows, 2'500u);
  EXPECT_EQ(q.post_rows, 10'000u);
  q = now(-1, 1.5);  // the rest of the ring before it
  EXPECT_EQ(capture_gate::resolve(q, kRing), "");
  EXPECT_EQ(q.pre_rows, 4'999u);
}

TEST(CaptureGate, TheWindowWithItsTriggerRowMustFitTheRing) {
  CaptureRequest fits = now(0.4999, 1.5);  // 4999 + 1 + 15000 = the ring
  EXPECT_EQ(capture_gate::resolve(fits, kRing), "");
  CaptureRequest q = now(0.5, 1.5);  // one row too many
  const std::string why = capture_gate::resolve(q, kRing);
  EXPECT_NE(why.find("pre-trigger 0.5 s and post-trigger 1.5 s do not fit"), std::string::npos) << why;
  EXPECT_NE(why.find("ring of 2 s ([axes.recorder] seconds)"), std::string::npos) << why;
  EXPECT_NE(why.find("at most 0.5 s before"), std::string::npos) << why;  // 4999 rows, printed to 3 digits
  EXPECT_EQ(q.pre_rows, kRingDefaultRows) << "a refused request is left as it was";
  EXPECT_EQ(q.post_rows, kRingDefaultRows);
  q = now(-1, 2.0);  // the trigger row leaves no room for 2 s after it
  EXPECT_NE(capture_gate::resolve(q, kRing).find("post-trigger 2 s does not fit the axis's recorder ring of 2 s"),
            std::string::npos);
  q = now(3.0, -1);
  EXPECT_NE(capture_gate::resolve(q, kRing), "");
}

TEST(CaptureGate, NonFiniteLengthsAreRefused) {
  CaptureRequest q = now(std::numeric_limits<double>::quiet_NaN(), -1);
  EXPECT_EQ(capture_gate::resolve(q, kRing), "capture lengths must be finite");
  q = now(-1, std::numeric_limits<double>::infinity());
  EXPECT_EQ(capture_gate::resolve(q, kRing), "capture lengths must be finite");
}

TEST(CaptureGate, AConditionNamesASignalOfTheCaptureFile) {
  CaptureRequest q = condition("following_error_m", 0.001);
  EXPECT_EQ(capture_gate::resolve(q, kRing), "");
  EXPECT_EQ(q.signal_index, recorder_signal_index("following_error_m"));
  EXPECT_GE(q.signal_index, 0);

  q = condition("following_error", 0.001);
  const std::string why = capture_gate::resolve(q, kRing);
  EXPECT_EQ(why.rfind("unknown signal 'following_error': one of seq, tick,", 0), 0u) << why;
  EXPECT_NE(why.find("following_error_m"), std::string::npos);
  EXPECT_EQ(q.signal_index, -1);
  q = condition("t", 0.0);  // a file's column, but no row's signal
  EXPECT_NE(capture_gate::resolve(q, kRing), "");
}

TEST(CaptureGate, AConditionsLevelMustBeFinite) {
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    CaptureRequest q = condition("position_m", bad);
    EXPECT_EQ(capture_gate::resolve(q, kRing), "the level must be a finite number");
    EXPECT_EQ(q.signal_index, -1);
  }
}

TEST(CaptureGate, DisarmNeedsNothing) {
  CaptureRequest q;
  q.action = CaptureAction::disarm;
  q.pre_s = std::numeric_limits<double>::quiet_NaN();  // not read
  EXPECT_EQ(capture_gate::resolve(q, kRing), "");
}

}  // namespace
}  // namespace hsa::daemon
