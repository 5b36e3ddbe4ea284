#include "daemon/rt/rt_executive.hpp"

#include <sched.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/rt/rt_counters.hpp"
#include "tests/daemon/rt_test_support.hpp"

namespace hsa::daemon {
namespace {

using ::testing::HasSubstr;
using testing::RecordingTask;
using testing::run_to_completion;

std::uint64_t sum(const LatencyHistogram::Counts& counts) {
  return std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
}

// Grants or refuses each request as told, without touching the process.
class FakePlatform : public RtPlatform {
 public:
  FakePlatform(int mlock_errno, int fifo_errno, int affinity_errno = 0)
      : mlock_errno_(mlock_errno), fifo_errno_(fifo_errno), affinity_errno_(affinity_errno) {}
  int lock_memory() noexcept override { return mlock_errno_; }
  int set_fifo_priority(int) noexcept override { return fifo_errno_; }
  int pin_to_cpu(int) noexcept override { return affinity_errno_; }

 private:
  int mlock_errno_;
  int fifo_errno_;
  int affinity_errno_;
};

TEST(RtExecutive, RunsTheTaskOnAConsistentTickGrid) {
  constexpr std::uint64_t kCycles = 2000;  // 0.2 s at 100 µs
  auto task = std::make_unique<RecordingTask>(kCycles);
  RtExecutive executive(RtConfig{}, *task);
  const RealtimeGrant grant = run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished()) << "the loop did not run " << kCycles << " cycles in 20 s";
  ASSERT_EQ(task->count(), kCycles) << "the loop ran a cycle after request_stop()";

  const RtStats s = executive.snapshot();
  EXPECT_EQ(s.cycles, kCycles);
  EXPECT_EQ(sum(s.lateness_histogram), kCycles);
  EXPECT_EQ(sum(s.execution_histogram), kCycles);
  EXPECT_GE(s.max_lateness_ns, 0);
  EXPECT_LE(s.lateness.p50_ns, s.lateness.p99_ns);
  EXPECT_LE(s.lateness.p99_ns, s.lateness.p999_ns);
  EXPECT_LE(s.lateness.p999_ns, s.max_lateness_ns);

  const CycleTiming& first = task->timing(0);
  EXPECT_EQ(first.tick, 0U);
  EXPECT_EQ(first.skipped, 0U);
  std::uint64_t overruns_seen = 0;
  std::uint64_t skips_seen = 0;
  for (std::size_t i = 0; i < kCycles; ++i) {
    const CycleTiming& t = task->timing(i);
    EXPECT_EQ(t.period_ns, 100'000);
    EXPECT_GE(t.woke_ns, t.scheduled_ns) << i;
    EXPECT_EQ(t.scheduled_ns, first.scheduled_ns + static_cast<std::int64_t>(t.tick) * t.period_ns) << i;
    EXPECT_TRUE(task->flag_seen(i)) << i;
    if (i > 0) {
      const CycleTiming& prev = task->timing(i - 1);
      EXPECT_EQ(t.tick, prev.tick + 1 + t.skipped) << i;
      EXPECT_EQ(t.overrun_streak, t.skipped > 0 ? prev.overrun_streak + 1 : 0) << i;
      overruns_seen += t.skipped > 0;
      skips_seen += t.skipped;
    }
  }
  // The stats also count the last cycle's overrun, which no later cycle saw.
  EXPECT_GE(s.overruns, overruns_seen);
  EXPECT_LE(s.overruns, overruns_seen + 1);
  EXPECT_GE(s.skipped_periods, skips_seen);
  EXPECT_FALSE(in_rt_cycle()) << "the flag is the RT thread's, never this one's";

  // Whatever was granted is what the thread really got.
  if (grant.sched_fifo) {
    EXPECT_EQ(task->policy(kCycles - 1), SCHED_FIFO);
    EXPECT_EQ(task->priority(kCycles - 1), 80);
  } else {
    EXPECT_NE(task->policy(kCycles - 1), SCHED_FIFO);
    std::printf("note: SCHED_FIFO refused here, the loop ran without it: %s\n", grant.detail.c_str());
  }
}

// Busy-waits 350 µs in one cycle of a 100 µs period: that cycle must overrun, and the executive must
// skip at least the three periods it missed rather than run them back to back.
class OverrunningTask : public RecordingTask {
 public:
  static constexpr std::uint64_t kSlowCycle = 100;
  using RecordingTask::RecordingTask;
  void work(std::uint64_t index) noexcept override {
    if (index == kSlowCycle) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(350);
      while (std::chrono::steady_clock::now() < until) {
      }
    }
  }
};

TEST(RtExecutive, SkipsThePeriodsAnOverrunMissed) {
  auto task = std::make_unique<OverrunningTask>(300);
  RtExecutive executive(RtConfig{}, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const CycleTiming& slow = task->timing(OverrunningTask::kSlowCycle);
  const CycleTiming& after = task->timing(OverrunningTask::kSlowCycle + 1);
  EXPECT_GE(after.skipped, 3U);
  EXPECT_GE(after.overrun_streak, 1U);
  EXPECT_EQ(after.tick, slow.tick + 1 + after.skipped);
  // Skipping, not bursting: the cycle after the overrun is scheduled after the slow one ended.
  EXPECT_GE(after.scheduled_ns, slow.woke_ns + 350'000);
  const RtStats s = executive.snapshot();
  EXPECT_GE(s.overruns, 1U);
  EXPECT_GE(s.skipped_periods, 3U);
  EXPECT_GE(s.max_execution_ns, 350'000);
  EXPECT_GE(s.max_overrun_streak, 1U);
}

TEST(RtExecutive, PinsTheThreadToTheConfiguredCpu) {
  cpu_set_t allowed;
  ASSERT_EQ(sched_getaffinity(0, sizeof(allowed), &allowed), 0);
  int cpu = 0;
  while (cpu < CPU_SETSIZE && !CPU_ISSET(cpu, &allowed)) {
    ++cpu;
  }
  RtConfig config;
  config.cpu = cpu;
  auto task = std::make_unique<RecordingTask>(200);
  RtExecutive executive(config, *task);
  const RealtimeGrant grant = run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  ASSERT_TRUE(grant.affinity) << grant.detail;
  for (std::size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(task->cpu(i), cpu) << i;
  }
}

TEST(RtExecutive, RequireRealtimeRefusesToStartAndSaysWhy) {
  FakePlatform refusing(ENOMEM, EPERM);
  RtConfig config;
  config.require_realtime = true;
  auto task = std::make_unique<RecordingTask>(10);
  RtExecutive executive(config, *task, refusing);
  task->attach(executive);
  try {
    (void)executive.start();
    FAIL() << "start() ran although SCHED_FIFO and mlockall were refused";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_THAT(what, HasSubstr("SCHED_FIFO priority 80 refused: Operation not permitted "
                                "(needs CAP_SYS_NICE or LimitRTPRIO)"));
    EXPECT_THAT(what, HasSubstr("mlockall(MCL_CURRENT|MCL_FUTURE) refused: Cannot allocate memory"));
    EXPECT_THAT(what, HasSubstr("require_realtime"));
  }
  EXPECT_FALSE(executive.running());
  EXPECT_EQ(task->count(), 0U);
  EXPECT_EQ(executive.cycles(), 0U);
}

TEST(RtExecutive, RequireRealtimeAlsoCoversTheCpuAffinity) {
  FakePlatform refusing(0, 0, EINVAL);
  RtConfig config;
  config.require_realtime = true;
  config.cpu = 3;
  auto task = std::make_unique<RecordingTask>(10);
  RtExecutive executive(config, *task, refusing);
  try {
    (void)executive.start();
    FAIL() << "start() ran although the CPU affinity was refused";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("CPU affinity to CPU 3 refused: Invalid argument"));
    EXPECT_THAT(std::string(e.what()), ::testing::Not(HasSubstr("SCHED_FIFO")));
  }
  EXPECT_EQ(task->count(), 0U);
}

TEST(RtExecutive, RefusalWithoutRequireRealtimeWarnsOnceAndRuns) {
  FakePlatform refusing(0, EPERM);
  auto task = std::make_unique<RecordingTask>(100);
  RtExecutive executive(RtConfig{}, *task, refusing);
  std::vector<std::string> warnings;
  executive.set_warning_handler([&warnings](const std::string& w) { warnings.push_back(w); });
  const RealtimeGrant grant = run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  EXPECT_FALSE(grant.sched_fifo);
  EXPECT_TRUE(grant.memory_locked);
  EXPECT_FALSE(grant.affinity);
  EXPECT_THAT(grant.detail, HasSubstr("SCHED_FIFO priority 80 refused: Operation not permitted"));
  ASSERT_EQ(warnings.size(), 1U);
  EXPECT_THAT(warnings[0], HasSubstr("SCHED_FIFO priority 80 refused"));
  EXPECT_EQ(executive.snapshot().cycles, 100U);
}

TEST(RtExecutive, FullGrantDoesNotWarn) {
  FakePlatform granting(0, 0);
  auto task = std::make_unique<RecordingTask>(10);
  RtExecutive executive(RtConfig{}, *task, granting);
  int warnings = 0;
  executive.set_warning_handler([&warnings](const std::string&) { ++warnings; });
  const RealtimeGrant grant = run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  EXPECT_TRUE(grant.sched_fifo);
  EXPECT_TRUE(grant.memory_locked);
  EXPECT_EQ(grant.detail, "SCHED_FIFO priority 80, memory locked, no CPU affinity asked");
  EXPECT_EQ(warnings, 0);
}

TEST(RtExecutive, RejectsABadPeriodOrPriority) {
  RecordingTask task(1);
  RtConfig zero_period;
  zero_period.period = std::chrono::nanoseconds{0};
  EXPECT_THROW(RtExecutive(zero_period, task), std::invalid_argument);
  RtConfig bad_priority;
  bad_priority.priority = 100;
  EXPECT_THROW(RtExecutive(bad_priority, task), std::invalid_argument);
}

TEST(RtExecutive, StartsOnceAndStopsIdempotently) {
  auto task = std::make_unique<RecordingTask>(10);
  RtExecutive executive(RtConfig{}, *task);
  run_to_completion(executive, *task);
  EXPECT_THROW((void)executive.start(), std::logic_error);
  executive.stop();
  EXPECT_FALSE(executive.running());
}

TEST(RtExecutive, RequestStopEndsTheLoopFromAnotherThread) {
  auto task = std::make_unique<RecordingTask>(UINT64_MAX);  // never stops by itself
  RtExecutive executive(RtConfig{}, *task);
  task->attach(executive);
  (void)executive.start();
  while (executive.cycles() < 50) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  executive.request_stop();
  executive.stop();  // joins: returns only because the loop saw the flag
  const std::uint64_t cycles = executive.cycles();
  EXPECT_GE(cycles, 50U);
  EXPECT_EQ(task->count(), cycles);
}

// A production build (no hsa_rt_counters): the weak counters report zero and say they are not real.
class AllocatingTask : public RecordingTask {
 public:
  using RecordingTask::RecordingTask;
  void work(std::uint64_t) noexcept override { held_ = std::make_unique<std::array<char, 64>>(); }

 private:
  std::unique_ptr<std::array<char, 64>> held_;
};

TEST(RtExecutive, WithoutTheCounterLibraryAllocationCountsAreZeroAndMarkedSo) {
  auto task = std::make_unique<AllocatingTask>(20);
  RtExecutive executive(RtConfig{}, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_FALSE(s.counters_linked);
  EXPECT_FALSE(rt_counters_linked());
  EXPECT_EQ(s.allocations, 0U);
  EXPECT_EQ(rt_allocations(), 0U);
}

}  // namespace
}  // namespace hsa::daemon
