// hsactl's ages of the values it shows (tools/hsactl/value_age.hpp): the status's rod ages with the
// time since its sample, and a value hsad marked stale is shown as STALE with its age.
#include <gtest/gtest.h>

#include "tools/hsactl/value_age.hpp"

namespace hsa::ctl {
namespace {

hsa::status_t status_with_sample(std::int64_t utime, std::int64_t sample_utime, std::int64_t age_us, bool stale) {
  hsa::status_t s{};
  s.utime = utime;
  s.sample_utime = sample_utime;
  s.position_age_us = age_us;
  s.position_stale = stale;
  return s;
}

// The sample's own age plus the time from the sample to the status: a sample that stopped coming
// ages with every status.
TEST(ValueAge, TheStatusPositionAgesWithTheTimeSinceItsSample) {
  const ValueAge live = status_position_age(status_with_sample(10'000'400, 10'000'000, 0, false));
  EXPECT_EQ(live.age_us, 400);
  EXPECT_FALSE(live.stale);
  const ValueAge frozen = status_position_age(status_with_sample(12'500'000, 12'499'800, 2'300'000, true));
  EXPECT_EQ(frozen.age_us, 2'300'200);
  EXPECT_TRUE(frozen.stale);
}

TEST(ValueAge, AStatusBeforeItsSampleDoesNotMakeTheValueYounger) {
  EXPECT_EQ(status_position_age(status_with_sample(100, 200, 50, false)).age_us, 50);
}

TEST(ValueAge, TextSaysStaleAndTheAge) {
  EXPECT_EQ(age_text({400, false}), "0.4 ms old");
  EXPECT_EQ(age_text({999'999, false}), "1000.0 ms old");
  EXPECT_EQ(age_text({2'310'000, true}), "STALE, 2.310 s old");
  EXPECT_EQ(age_text({-1, false}), "no such input");
}

// Each input's age with its own stale bit; the inputs the axis lacks are left out of the text.
TEST(ValueAge, TelemetryInputsCarryTheirOwnStaleBits) {
  hsa::telemetry_t t{};
  t.position_age_us = 2'000'000;
  t.pressure_a_age_us = 100;
  t.pressure_b_age_us = 100;
  t.spool_age_us = -1;
  t.estop_age_us = 150'000;
  t.stale = hsa::telemetry_t::STALE_POSITION | hsa::telemetry_t::STALE_ESTOP;
  const auto inputs = telemetry_inputs(t);
  EXPECT_STREQ(inputs[0].key, "position");
  EXPECT_TRUE(inputs[0].age.stale);
  EXPECT_FALSE(inputs[1].age.stale);
  EXPECT_FALSE(inputs[2].age.stale);
  EXPECT_EQ(inputs[3].age.age_us, -1);
  EXPECT_TRUE(inputs[4].age.stale);
  EXPECT_EQ(inputs_text(t),
            "position STALE, 2.000 s old, pressure A 0.1 ms old, pressure B 0.1 ms old, e-stop STALE, 150.0 ms old");
}

}  // namespace
}  // namespace hsa::ctl
