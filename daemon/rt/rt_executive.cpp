#include "daemon/rt/rt_executive.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "daemon/rt/next_deadline.hpp"
#include "daemon/rt/rt_counters.hpp"
#include "daemon/rt/rt_cycle_flag.hpp"
#include "drivers/clock.hpp"

namespace hsa::daemon {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
// Stack beyond the pre-faulted part, for the set-up code and whatever the cycle uses past it.
constexpr std::size_t kStackMargin = 256 * 1024;

void sleep_until(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // A signal handler (SIGTERM → request_stop) interrupts the sleep; the absolute deadline makes
  // resuming it exact.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

SteadyStateCounts read_counts() noexcept {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return {static_cast<std::uint64_t>(usage.ru_minflt), static_cast<std::uint64_t>(usage.ru_majflt),
          rt_allocations(), rt_deallocations(), rt_lock_acquisitions()};
}

// Writes one byte per page of `bytes` of fresh stack below the caller's frame, so the kernel maps
// those pages now rather than on the cycle's first deep call. Writes, not reads: a read could map
// the shared zero page and leave the write fault for later. noinline so the alloca'd area really is
// below the frames that call the cycle.
[[gnu::noinline]] void prefault_stack(std::size_t bytes) noexcept {
  if (bytes == 0) {
    return;
  }
  auto* area = static_cast<volatile unsigned char*>(__builtin_alloca(bytes));
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  for (std::size_t i = 0; i < bytes; i += page) {
    area[i] = 0;
  }
  area[bytes - 1] = 0;
}

std::string errno_text(int err) {
  char buffer[128];
  return strerror_r(err, buffer, sizeof(buffer));  // GNU strerror_r returns the message
}

void warn_to_stderr(const std::string& message) { std::fprintf(stderr, "hsad: warning: %s\n", message.c_str()); }

}  // namespace

RtExecutive::RtExecutive(RtConfig config, CycleTask& task, RtPlatform& platform)
    : config_(config), task_(task), platform_(platform), warn_(warn_to_stderr), recorder_(config.warmup_cycles) {
  if (config_.period.count() <= 0) {
    throw std::invalid_argument("RT period must be positive, got " + std::to_string(config_.period.count()) + " ns");
  }
  if (config_.priority < 1 || config_.priority > 99) {
    throw std::invalid_argument("SCHED_FIFO priority must be in 1..99, got " + std::to_string(config_.priority));
  }
}

RtExecutive::~RtExecutive() { stop(); }

void RtExecutive::set_warning_handler(WarningHandler handler) { warn_ = std::move(handler); }

RealtimeGrant RtExecutive::start() {
  if (started_) {
    throw std::logic_error("RtExecutive::start() called twice");
  }
  started_ = true;

  pthread_attr_t attr;
  pthread_attr_init(&attr);
  std::size_t stack = 0;
  pthread_attr_getstacksize(&attr, &stack);
  const std::size_t wanted = config_.stack_prefault_bytes + kStackMargin;
  if (stack < wanted) {
    pthread_attr_setstacksize(&attr, wanted);
  }
  const int err = pthread_create(&thread_, &attr, &RtExecutive::thread_main, this);
  pthread_attr_destroy(&attr);
  if (err != 0) {
    throw std::system_error(err, std::generic_category(), "cannot create the RT thread");
  }
  setup_state_.wait(kPending, std::memory_order_acquire);

  grant_.affinity = config_.cpu >= 0 && affinity_errno_ == 0;
  grant_.memory_locked = mlock_errno_ == 0;
  grant_.sched_fifo = fifo_errno_ == 0;
  std::string refused;
  const auto refuse = [&refused](const std::string& what) { refused += (refused.empty() ? "" : "; ") + what; };
  if (fifo_errno_ != 0) {
    refuse("SCHED_FIFO priority " + std::to_string(config_.priority) + " refused: " + errno_text(fifo_errno_) +
           " (needs CAP_SYS_NICE or LimitRTPRIO)");
  }
  if (mlock_errno_ != 0) {
    refuse("mlockall(MCL_CURRENT|MCL_FUTURE) refused: " + errno_text(mlock_errno_) +
           " (needs CAP_IPC_LOCK or LimitMEMLOCK=infinity)");
  }
  if (config_.cpu >= 0 && affinity_errno_ != 0) {
    refuse("CPU affinity to CPU " + std::to_string(config_.cpu) + " refused: " + errno_text(affinity_errno_) +
           " (the CPU must exist and be in the process's allowed set: CPUAffinity, cpuset)");
  }

  if (setup_state_.load(std::memory_order_acquire) == kRefused) {
    pthread_join(thread_, nullptr);
    throw std::runtime_error("real-time required (require_realtime = true) but refused: " + refused);
  }
  running_ = true;
  if (refused.empty()) {
    grant_.detail = "SCHED_FIFO priority " + std::to_string(config_.priority) + ", memory locked, " +
                    (config_.cpu >= 0 ? "pinned to CPU " + std::to_string(config_.cpu) : "no CPU affinity asked");
  } else {
    grant_.detail = refused;
    if (warn_) {
      warn_("running without full real-time: " + refused + "; the loop runs but its timing is not guaranteed");
    }
  }
  return grant_;
}

void RtExecutive::request_stop() noexcept { stop_requested_.store(true, std::memory_order_release); }

void RtExecutive::stop() {
  request_stop();
  if (running_) {
    pthread_join(thread_, nullptr);
    running_ = false;
  }
}

void* RtExecutive::thread_main(void* self) noexcept {
  static_cast<RtExecutive*>(self)->run();
  return nullptr;
}

void RtExecutive::run() noexcept {
  pthread_setname_np(pthread_self(), "hsa-rt");
  // Affinity first so the pages locked and touched below are allocated from the RT CPU's node.
  affinity_errno_ = config_.cpu >= 0 ? platform_.pin_to_cpu(config_.cpu) : 0;
  mlock_errno_ = platform_.lock_memory();
  fifo_errno_ = platform_.set_fifo_priority(config_.priority);
  prefault_stack(config_.stack_prefault_bytes);

  const bool refused = fifo_errno_ != 0 || mlock_errno_ != 0 || affinity_errno_ != 0;
  const bool go = !(refused && config_.require_realtime);
  setup_state_.store(go ? kReady : kRefused, std::memory_order_release);
  setup_state_.notify_one();
  if (go) {
    loop();
  }
}

void RtExecutive::loop() noexcept {
  const std::int64_t period = config_.period.count();
  recorder_.begin(read_counts());
  std::int64_t scheduled = io::monotonic_ns() + period;
  std::uint64_t tick = 0;
  std::uint64_t skipped = 0;
  while (!stop_requested_.load(std::memory_order_acquire)) {
    sleep_until(scheduled);
    t_in_rt_cycle = true;
    const std::int64_t woke = io::monotonic_ns();
    task_.cycle(CycleTiming{scheduled, woke, period, tick, skipped, recorder_.overrun_streak()});
    const std::int64_t end = io::monotonic_ns();
    const NextDeadline next = next_deadline(end, scheduled, period);
    const bool counts_due = recorder_.counts_due();
    recorder_.record(CycleSample{woke - scheduled, end - woke, next.skipped,
                                 counts_due ? std::optional(read_counts()) : std::nullopt});
    t_in_rt_cycle = false;
    tick += 1 + next.skipped;
    skipped = next.skipped;
    scheduled = next.next_ns;
  }
  recorder_.record_final_counts(read_counts());
}

}  // namespace hsa::daemon
