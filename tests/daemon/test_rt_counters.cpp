// The steady-state counters of a test build: this executable links
// hsa_rt_counters, so allocations and locks made with the RT-cycle flag set are counted.
#include "daemon/rt/rt_counters.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <shared_mutex>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/rt/rt_cycle_flag.hpp"
#include "daemon/rt/rt_executive.hpp"
#include "tests/daemon/rt_test_support.hpp"

namespace hsa::daemon {
namespace {

using testing::RecordingTask;
using testing::run_to_completion;

const std::size_t kPage = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));

// Grants SCHED_FIFO and affinity as asked but does not lock memory, so page faults stay visible.
class NoMlockPlatform : public RtPlatform {
 public:
  int lock_memory() noexcept override { return EPERM; }
  int set_fifo_priority(int priority) noexcept override { return linux_rt_platform().set_fifo_priority(priority); }
  int pin_to_cpu(int cpu) noexcept override { return linux_rt_platform().pin_to_cpu(cpu); }
};

// A warning handler that keeps the refused mlockall out of the test output.
void quiet(const std::string&) {}

TEST(RtCounters, TheCounterLibraryIsLinked) { EXPECT_TRUE(rt_counters_linked()); }

TEST(RtCounters, CountsEveryOperatorNewFormOnlyInsideTheRtCycle) {
  const std::uint64_t allocations = rt_allocations();
  const std::uint64_t deallocations = rt_deallocations();
  {
    auto outside = std::make_unique<int>(1);
    EXPECT_NE(outside, nullptr);
  }
  EXPECT_EQ(rt_allocations(), allocations);
  EXPECT_EQ(rt_deallocations(), deallocations);
  {
    RtCycleScope in_cycle;
    // Explicit operator calls: a new-expression paired with its delete may be elided by the compiler.
    ::operator delete(::operator new(16));
    ::operator delete[](::operator new[](16));
    ::operator delete(::operator new(16, std::nothrow), std::nothrow);
    ::operator delete[](::operator new[](16, std::nothrow), std::nothrow);
    ::operator delete(::operator new(16, std::align_val_t{64}), std::align_val_t{64});
    ::operator delete[](::operator new[](16, std::align_val_t{64}), std::align_val_t{64});
    ::operator delete(::operator new(16, std::align_val_t{64}, std::nothrow), std::align_val_t{64}, std::nothrow);
    ::operator delete[](::operator new[](16, std::align_val_t{64}, std::nothrow), std::align_val_t{64},
                        std::nothrow);
    ::operator delete(::operator new(16), std::size_t{16});
    ::operator delete[](::operator new[](16), std::size_t{16});
    ::operator delete(::operator new(16, std::align_val_t{64}), std::size_t{16}, std::align_val_t{64});
    ::operator delete[](::operator new[](16, std::align_val_t{64}), std::size_t{16}, std::align_val_t{64});
    void* aligned = ::operator new(16, std::align_val_t{256});
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(aligned) % 256, 0U);
    ::operator delete(aligned, std::align_val_t{256});
  }
  EXPECT_EQ(rt_allocations() - allocations, 13U);
  EXPECT_EQ(rt_deallocations() - deallocations, 13U);
  EXPECT_FALSE(in_rt_cycle());
}

TEST(RtCounters, CountsMutexAndRwlockAcquisitionsOnlyInsideTheRtCycle) {
  std::mutex mutex;
  std::shared_mutex shared;
  const std::uint64_t before = rt_lock_acquisitions();
  {
    std::lock_guard lock(mutex);
  }
  EXPECT_EQ(rt_lock_acquisitions(), before);
  {
    RtCycleScope in_cycle;
    mutex.lock();
    mutex.unlock();
    ASSERT_TRUE(mutex.try_lock());
    mutex.unlock();
    shared.lock_shared();
    shared.unlock_shared();
    shared.lock();
    shared.unlock();
  }
  EXPECT_EQ(rt_lock_acquisitions() - before, 4U);
}

TEST(RtCounters, AQuietTaskMakesNoAllocationLockOrSteadyPageFault) {
  constexpr std::uint64_t kCycles = 1000;
  auto task = std::make_unique<RecordingTask>(kCycles);
  RtConfig config;
  config.warmup_cycles = 100;
  RtExecutive executive(config, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_TRUE(s.counters_linked);
  EXPECT_TRUE(s.steady);
  EXPECT_EQ(s.allocations, 0U);
  EXPECT_EQ(s.deallocations, 0U);
  EXPECT_EQ(s.locks, 0U);
  EXPECT_EQ(s.steady_minor_faults, 0U);
  EXPECT_EQ(s.steady_major_faults, 0U);
}

class AllocatingTask : public RecordingTask {
 public:
  using RecordingTask::RecordingTask;
  void work(std::uint64_t) noexcept override { held_ = std::make_unique<std::array<char, 64>>(); }

 private:
  std::unique_ptr<std::array<char, 64>> held_;
};

TEST(RtCounters, AnAllocatingTaskIsCounted) {
  constexpr std::uint64_t kCycles = 200;
  auto task = std::make_unique<AllocatingTask>(kCycles);
  RtConfig config;
  config.warmup_cycles = 100;
  RtExecutive executive(config, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_EQ(s.allocations, kCycles);
  EXPECT_EQ(s.deallocations, kCycles - 1);  // the first cycle replaced nothing
  EXPECT_EQ(s.steady_allocations, kCycles - 100);
  EXPECT_EQ(s.locks, 0U);
}

class LockingTask : public RecordingTask {
 public:
  using RecordingTask::RecordingTask;
  void work(std::uint64_t) noexcept override {
    { std::lock_guard lock(mutex_); }
    { std::shared_lock lock(shared_); }
  }

 private:
  std::mutex mutex_;
  std::shared_mutex shared_;
};

TEST(RtCounters, ALockingTaskIsCounted) {
  constexpr std::uint64_t kCycles = 200;
  auto task = std::make_unique<LockingTask>(kCycles);
  RtConfig config;
  config.warmup_cycles = 100;
  RtExecutive executive(config, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_EQ(s.locks, 2 * kCycles);
  EXPECT_EQ(s.steady_locks, 2 * (kCycles - 100));
  EXPECT_EQ(s.allocations, 0U);
}

// Writes one byte per page of a buffer that was filled before the executive started.
class PrefaultedMemoryTask : public RecordingTask {
 public:
  PrefaultedMemoryTask(std::uint64_t cycles, std::vector<unsigned char>& buffer)
      : RecordingTask(cycles), buffer_(buffer) {}
  void work(std::uint64_t index) noexcept override {
    for (std::size_t i = 0; i < buffer_.size(); i += kPage) {
      buffer_[i] = static_cast<unsigned char>(index);
    }
  }

 private:
  std::vector<unsigned char>& buffer_;
};

TEST(RtCounters, TouchingOnlyPrefaultedMemoryHasNoSteadyPageFault) {
  std::vector<unsigned char> buffer(1 << 20);
  std::memset(buffer.data(), 1, buffer.size());
  constexpr std::uint64_t kCycles = 1000;
  auto task = std::make_unique<PrefaultedMemoryTask>(kCycles, buffer);
  RtConfig config;
  config.warmup_cycles = 100;
  RtExecutive executive(config, *task);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_TRUE(s.steady);
  EXPECT_EQ(s.steady_minor_faults, 0U);
  EXPECT_EQ(s.steady_major_faults, 0U);
}

// After the warm-up, maps fresh anonymous pages in some cycles and writes each of them once.
class FreshPagesTask : public RecordingTask {
 public:
  static constexpr std::size_t kPages = 16;
  static constexpr std::uint64_t kFirst = 60;
  static constexpr std::uint64_t kCount = 10;
  using RecordingTask::RecordingTask;
  void work(std::uint64_t index) noexcept override {
    if (index < kFirst || index >= kFirst + kCount) {
      return;
    }
    void* area = mmap(nullptr, kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (area == MAP_FAILED) {
      return;
    }
    auto* bytes = static_cast<volatile unsigned char*>(area);
    for (std::size_t p = 0; p < kPages; ++p) {
      bytes[p * kPage] = 1;
    }
    munmap(area, kPages * kPage);
  }
};

TEST(RtCounters, TouchingFreshPagesIsCountedAsSteadyPageFaults) {
  munlockall();  // an earlier test in this process may have locked (and so populated) future mappings
  NoMlockPlatform platform;
  constexpr std::uint64_t kCycles = 100;
  auto task = std::make_unique<FreshPagesTask>(kCycles);
  RtConfig config;
  config.warmup_cycles = 50;
  RtExecutive executive(config, *task, platform);
  executive.set_warning_handler(quiet);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_GE(s.steady_minor_faults, FreshPagesTask::kPages * FreshPagesTask::kCount);
  EXPECT_GE(s.minor_faults, s.steady_minor_faults);
}

// From cycle 1 on, writes every page of 1 MiB of its own stack.
class DeepStackTask : public RecordingTask {
 public:
  static constexpr std::size_t kStackBytes = 1 << 20;
  using RecordingTask::RecordingTask;
  void work(std::uint64_t index) noexcept override {
    if (index >= 1) {
      use_stack(index);
    }
  }

 private:
  [[gnu::noinline]] static void use_stack(std::uint64_t index) noexcept {
    auto* area = static_cast<volatile unsigned char*>(__builtin_alloca(kStackBytes));
    for (std::size_t i = 0; i < kStackBytes; i += kPage) {
      area[i] = static_cast<unsigned char>(index);
    }
  }
};

TEST(RtCounters, ThePrefaultedStackHasNoSteadyPageFault) {
  // Without mlockall only the pre-faulting puts these stack pages in place. 9 MiB makes the thread's
  // stack larger than glibc's 8 MiB default, so it is freshly mapped, not a cached stack an earlier
  // test already touched.
  munlockall();
  NoMlockPlatform platform;
  RtConfig config;
  config.stack_prefault_bytes = 9 << 20;
  config.warmup_cycles = 1;  // cycle 0 may fault in the task's code pages
  constexpr std::uint64_t kCycles = 100;
  auto task = std::make_unique<DeepStackTask>(kCycles);
  RtExecutive executive(config, *task, platform);
  executive.set_warning_handler(quiet);
  run_to_completion(executive, *task);
  ASSERT_TRUE(task->finished());
  const RtStats s = executive.snapshot();
  EXPECT_TRUE(s.steady);
  EXPECT_EQ(s.steady_minor_faults, 0U);
  EXPECT_EQ(s.steady_major_faults, 0U);
}

}  // namespace
}  // namespace hsa::daemon
