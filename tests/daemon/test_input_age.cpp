// daemon/axis/input_age.hpp: the age of an input's value and its stale mark, as status and
// telemetry carry them.
#include <gtest/gtest.h>

#include <cstdint>

#include "daemon/axis/input_age.hpp"
#include "drivers/signal.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t kStaleAfterNs = 100'000'000;  // input_stale_s = 0.1

io::AnalogSample sample_at(std::int64_t stamp_ns, io::SampleStatus status = io::SampleStatus::ok) {
  return {1.0, io::Timestamp{stamp_ns}, status};
}

TEST(InputAge, IsTheCycleTimeMinusTheSamplesTimestamp) {
  EXPECT_EQ(input_age(sample_at(5'000'000), 5'000'000, kStaleAfterNs).age_ns, 0);
  EXPECT_EQ(input_age(sample_at(5'000'000), 7'300'000, kStaleAfterNs).age_ns, 2'300'000);
  const io::DigitalSample estop{true, io::Timestamp{1'000}, io::SampleStatus::ok};
  EXPECT_EQ(input_age(estop, 4'000, kStaleAfterNs).age_ns, 3'000);
}

// Live up to the threshold itself, stale past it: the supervisor's input_stale bound.
TEST(InputAge, IsStaleOnlyPastTheThreshold) {
  const std::int64_t stamp = 1'000'000'000;
  EXPECT_FALSE(input_age(sample_at(stamp), stamp + kStaleAfterNs, kStaleAfterNs).stale);
  const InputAge past = input_age(sample_at(stamp), stamp + kStaleAfterNs + 1, kStaleAfterNs);
  EXPECT_TRUE(past.stale);
  EXPECT_EQ(past.age_ns, kStaleAfterNs + 1);
}

// A sample that is not ok is no live value however new: a disconnected sensor, a bus error.
TEST(InputAge, ASampleThatIsNotOkIsStaleWhateverItsAge) {
  for (const auto status : {io::SampleStatus::disconnected, io::SampleStatus::out_of_range}) {
    const InputAge a = input_age(sample_at(10, status), 10, kStaleAfterNs);
    EXPECT_TRUE(a.stale) << to_string(status);
    EXPECT_EQ(a.age_ns, 0);
  }
}

// A timestamp ahead of the cycle (a device's clock ahead of hsad's) is no negative age: −1 means
// "no such input" on the wire.
TEST(InputAge, ATimestampAheadOfTheCycleIsAgeZero) {
  const InputAge a = input_age(sample_at(2'000), 1'000, kStaleAfterNs);
  EXPECT_EQ(a.age_ns, 0);
  EXPECT_FALSE(a.stale);
}

// The default: what an unbound input reports.
TEST(InputAge, AnUnboundInputHasAgeMinusOne) {
  EXPECT_EQ(InputAge{}.age_ns, -1);
  EXPECT_FALSE(InputAge{}.stale);
}

}  // namespace
}  // namespace hsa::daemon
