// The flight recorder's condition trigger (daemon/recorder/capture_condition.hpp) and its place in
// AxisRecorder: crossings (not levels) fire, above and below, single-shot disarms, repeat fires
// again after its capture is handed off, a crossing while a capture collects is merged and counted,
// the signal table matches the capture file's columns, and the RT side allocates nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "daemon/recorder/axis_recorder.hpp"
#include "daemon/recorder/capture_condition.hpp"
#include "daemon/recorder/recorder_signals.hpp"
#include "tests/support/counting_allocator.hpp"

namespace hsa::daemon {
namespace {

const int kError = recorder_signal_index("following_error_m");
const int kExec = recorder_signal_index("exec_ns");

RecorderRow row_with_error(double e) {
  RecorderRow r;
  r.following_error_m = e;
  return r;
}

// Which of `values` fire the condition (their indices).
std::vector<std::size_t> firing(CaptureCondition& c, const std::vector<double>& values) {
  std::vector<std::size_t> fired;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (c.evaluate(row_with_error(values[i]))) fired.push_back(i);
  }
  return fired;
}

TEST(RecorderSignals, TheTableIsTheCaptureFilesColumnsInOrderAndReadsTheirMembers) {
  std::vector<std::string> names;
#define HSA_TEST_NAME(name, unit, expr) names.push_back(name);
  HSA_RECORDER_SIGNALS(HSA_TEST_NAME)
#undef HSA_TEST_NAME
  ASSERT_EQ(names.size(), kRecorderSignalCount);
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(kRecorderSignals[i].name, names[i]);
    EXPECT_EQ(recorder_signal_index(names[i]), static_cast<int>(i));
  }
  EXPECT_EQ(recorder_signal_index("t"), -1);  // not a row's signal
  EXPECT_EQ(recorder_signal_index("following_error"), -1);
  RecorderRow r;
  r.following_error_m = 0.25;
  r.exec_ns = 4321;
  r.pressure_b_pa = 1.5e6;
  EXPECT_EQ(kRecorderSignals[kError].read(r), 0.25);
  EXPECT_EQ(kRecorderSignals[kExec].read(r), 4321.0);
  EXPECT_EQ(kRecorderSignals[recorder_signal_index("pressure_b_pa")].read(r), 1.5e6);
}

TEST(CaptureCondition, AboveFiresOnTheFirstRowOverTheLevelAfterOneThatWasNot) {
  CaptureCondition c;
  c.arm({.signal = kError, .crossing = Crossing::above, .level = 0.001, .repeat = true});
  // Equal to the level is not above; the crossing is row 3.
  EXPECT_EQ(firing(c, {0.0, 0.0005, 0.001, 0.0011, 0.002, 0.0005, 0.003}), (std::vector<std::size_t>{3, 6}));
}

TEST(CaptureCondition, BelowFiresOnAFallingCrossing) {
  CaptureCondition c;
  c.arm({.signal = kError, .crossing = Crossing::below, .level = -0.001, .repeat = true});
  EXPECT_EQ(firing(c, {0.0, -0.001, -0.0012, -0.002, 0.0, -0.5}), (std::vector<std::size_t>{2, 5}));
}

TEST(CaptureCondition, ArmedWhileBeyondTheLevelWaitsForTheNextCrossing) {
  CaptureCondition c;
  c.arm({.signal = kError, .crossing = Crossing::above, .level = 0.001});
  EXPECT_EQ(firing(c, {0.01, 0.02, 0.0, 0.01}), (std::vector<std::size_t>{3}));
}

TEST(CaptureCondition, SingleShotDisarmsWhenItFires) {
  CaptureCondition c;
  c.arm({.signal = kError, .crossing = Crossing::above, .level = 0.001, .repeat = false});
  EXPECT_TRUE(c.armed());
  EXPECT_EQ(firing(c, {0.0, 0.01, 0.0, 0.01, 0.0, 0.01}), (std::vector<std::size_t>{1}));
  EXPECT_FALSE(c.armed());
}

TEST(CaptureCondition, ANanRowIsNeverBeyondAndCountsAsBelowForTheNextCrossing) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CaptureCondition c;
  c.arm({.signal = kError, .crossing = Crossing::above, .level = 0.001, .repeat = true});
  EXPECT_EQ(firing(c, {0.0, nan, 0.01, nan, 0.01}), (std::vector<std::size_t>{2, 4}));
}

TEST(CaptureCondition, DisarmedOrWithoutASignalItNeverFires) {
  CaptureCondition c;
  EXPECT_EQ(firing(c, {0.0, 1.0}), std::vector<std::size_t>{});
  c.arm({.signal = -1, .level = 0.5});
  EXPECT_FALSE(c.armed());
  c.arm({.signal = static_cast<int>(kRecorderSignalCount), .level = 0.5});
  EXPECT_FALSE(c.armed());
  c.arm({.signal = kError, .level = 0.5, .repeat = true});
  c.disarm();
  EXPECT_EQ(firing(c, {0.0, 1.0}), std::vector<std::size_t>{});
}

TEST(CaptureCondition, DescribesItselfAsTheFileAndStatusSayIt) {
  EXPECT_EQ(describe({.signal = kError, .crossing = Crossing::above, .level = 0.001}), "following_error_m above 0.001");
  EXPECT_EQ(describe({.signal = kExec, .crossing = Crossing::below, .level = -2.5e-7}), "exec_ns below -2.5e-07");
}

// --- AxisRecorder: the condition on the RT cycle's committed rows ---------------------------------

// One RT cycle's part that needs no loop: the row's fields, then commit (where the condition looks).
void cycle(AxisRecorder& rec, std::uint64_t tick, double error, std::int32_t exec_ns = 1000) {
  RecorderRow& r = rec.ring().slot();
  r = RecorderRow{};
  r.seq = tick;
  r.tick = tick;
  r.t_ns = static_cast<std::int64_t>(tick) * 100'000;
  r.following_error_m = error;
  rec.commit(exec_ns);
}

CaptureRequest arm(double level, bool repeat, std::uint32_t pre, std::uint32_t post, const char* signal = "following_error_m") {
  CaptureRequest q;
  q.action = CaptureAction::arm;
  q.signal_index = static_cast<std::int16_t>(recorder_signal_index(signal));
  q.crossing = Crossing::above;
  q.level = level;
  q.repeat = repeat;
  q.pre_rows = pre;
  q.post_rows = post;
  return q;
}

TEST(AxisRecorderCondition, TheCrossingRowIsTheTriggerWithTheAskedWindowAndTheConditionInTheCapture) {
  AxisRecorder rec(std::make_unique<CaptureRing>(1000, 100));
  std::uint64_t t = 0;
  for (; t < 500; ++t) cycle(rec, t, 0.0);
  rec.apply(arm(0.001, false, 50, 20), 7);
  EXPECT_EQ(rec.armed_ticket(), 7u);
  for (; t < 600; ++t) cycle(rec, t, 0.0);
  const std::uint64_t crossing = t;
  for (int i = 0; i < 30; ++i, ++t) cycle(rec, t, 0.002);
  const Capture* c = rec.ring().take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.kind, TriggerKind::condition);
  EXPECT_EQ(c->why.tick, crossing);
  EXPECT_EQ(c->row(c->trigger_offset()).tick, crossing);
  EXPECT_EQ(c->trigger_offset(), 50u);                     // --pre
  EXPECT_EQ(c->size() - c->trigger_offset() - 1, 20u);     // --post
  EXPECT_EQ(c->why.signal, kError);
  EXPECT_EQ(c->why.level, 0.001);
  EXPECT_EQ(rec.armed_ticket(), 0u) << "a single-shot condition that fired is no longer armed";
  rec.ring().release();
  for (int i = 0; i < 10; ++i, ++t) cycle(rec, t, 0.0);
  for (int i = 0; i < 100; ++i, ++t) cycle(rec, t, 0.002);
  EXPECT_EQ(rec.ring().take(), nullptr) << "single-shot fired again";
  EXPECT_EQ(rec.ring().counts().triggers, 1u);
}

TEST(AxisRecorderCondition, RepeatFiresAgainAfterHandOffAndMergesACrossingWhileItsCaptureCollects) {
  AxisRecorder rec(std::make_unique<CaptureRing>(1000, 100));
  rec.apply(arm(0.001, true, 10, 40), 9);
  std::uint64_t t = 0;
  for (; t < 200; ++t) cycle(rec, t, 0.0);
  const std::uint64_t first = t;
  cycle(rec, t++, 0.002);                       // crossing 1
  for (int i = 0; i < 10; ++i) cycle(rec, t++, 0.0);
  cycle(rec, t++, 0.002);                       // crossing 2, while capture 1 collects: merged
  for (int i = 0; i < 40; ++i) cycle(rec, t++, 0.0);
  const Capture* c = rec.ring().take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.tick, first);
  EXPECT_EQ(c->merged, 1u);
  rec.ring().release();
  EXPECT_EQ(rec.armed_ticket(), 9u) << "repeat stays armed";
  const std::uint64_t third = t;
  cycle(rec, t++, 0.002);                       // crossing 3, after hand-off: a capture of its own
  for (int i = 0; i < 40; ++i) cycle(rec, t++, 0.0);
  c = rec.ring().take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.tick, third);
  EXPECT_EQ(c->merged, 0u);
  const CaptureRingCounts n = rec.ring().counts();
  EXPECT_EQ(n.triggers, 3u);
  EXPECT_EQ(n.merged, 1u);
  EXPECT_EQ(n.frozen, 2u);
  rec.apply(CaptureRequest{.action = CaptureAction::disarm}, 10);
  EXPECT_EQ(rec.armed_ticket(), 0u);
}

TEST(AxisRecorderCondition, ExecNsIsWatchedOnTheCompleteRow) {
  AxisRecorder rec(std::make_unique<CaptureRing>(100, 10));
  rec.apply(arm(50'000, false, kRingDefaultRows, kRingDefaultRows, "exec_ns"), 3);
  std::uint64_t t = 0;
  for (; t < 50; ++t) cycle(rec, t, 0.0, 20'000);
  const std::uint64_t slow = t;
  cycle(rec, t++, 0.0, 80'000);
  for (int i = 0; i < 10; ++i) cycle(rec, t++, 0.0, 20'000);
  const Capture* c = rec.ring().take();
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->why.tick, slow);
  EXPECT_EQ(c->row(c->trigger_offset()).exec_ns, 80'000);
  EXPECT_EQ(c->size() - c->trigger_offset() - 1, 10u);  // the ring's own post rows
}

TEST(AxisRecorderCondition, ArmingAndEvaluatingAllocateNothing) {
  AxisRecorder rec(std::make_unique<CaptureRing>(1000, 100));
  const CaptureRequest request = arm(0.001, true, 100, 100);
  const long before = test::thread_allocations();
  rec.apply(request, 1);
  std::uint64_t t = 0;
  for (int k = 0; k < 20; ++k) {
    for (int i = 0; i < 500; ++i) cycle(rec, t++, i == 250 ? 0.01 : 0.0);
    if (rec.ring().take() != nullptr) rec.ring().release();
  }
  EXPECT_EQ(test::thread_allocations() - before, 0);
  EXPECT_EQ(rec.ring().counts().frozen, 20u);
}

}  // namespace
}  // namespace hsa::daemon
