#include "daemon/recorder/capture_writer.hpp"

#include <time.h>

#include <chrono>
#include <cstdio>
#include <exception>

namespace hsa::daemon {
namespace {

std::int64_t clock_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

CaptureWriter::CaptureWriter(std::filesystem::path folder, CaptureFolderLimits limits, std::vector<Axis> axes)
    : folder_(std::move(folder)), limits_(limits), axes_(std::move(axes)), counts_(axes_.size()) {}

CaptureWriter::~CaptureWriter() { stop(); }

void CaptureWriter::start() {
  thread_ = std::thread([this] {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      lock.unlock();
      poll();
      lock.lock();
      wake_.wait_for(lock, std::chrono::milliseconds(20), [this] { return stop_; });
    }
  });
}

void CaptureWriter::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  poll();
}

void CaptureWriter::poll() {
  std::lock_guard one(writing_);  // poll() from the thread and from stop(): one writer at a time
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (const Capture* c = axes_[i].ring->take()) {
      write(i, *c);
      axes_[i].ring->release();
    }
  }
}

void CaptureWriter::write(std::size_t index, const Capture& capture) {
  const Axis& axis = axes_[index];
  Counts& n = counts_[index];
  // The trigger's wall-clock time, from its monotonic time (the daemon's clock is CLOCK_MONOTONIC).
  const std::int64_t age_ns = clock_ns(CLOCK_MONOTONIC) - (axis.context.epoch_ns + capture.why.t_ns);
  const std::string name =
      capture_file_name(axis.context.axis, clock_ns(CLOCK_REALTIME) - age_ns, capture_reason_word(capture.why));
  const std::filesystem::path path = folder_ / name;
  try {
    const std::uint64_t bytes = write_capture_mat(path.string(), capture, axis.context);
    n.written.fetch_add(1, std::memory_order_relaxed);
    n.bytes.fetch_add(bytes, std::memory_order_relaxed);
    {
      std::lock_guard lock(mutex_);
      last_file_ = path.string();
    }
    std::fprintf(stderr, "hsad: flight recorder: axis '%s': %s: %zu rows (%zu before the trigger), %llu bytes: %s\n",
                 axis.context.axis.c_str(), path.c_str(), capture.size(), capture.trigger_offset(),
                 static_cast<unsigned long long>(bytes), capture_reason(capture.why).c_str());
  } catch (const std::exception& e) {
    n.failed.fetch_add(1, std::memory_order_relaxed);
    std::fprintf(stderr, "hsad: flight recorder: axis '%s': capture not written: %s\n", axis.context.axis.c_str(),
                 e.what());
    return;
  }
  try {
    n.deleted.fetch_add(prune_captures(folder_, limits_), std::memory_order_relaxed);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hsad: flight recorder: cannot bound %s: %s\n", folder_.c_str(), e.what());
  }
}

RecorderCounters CaptureWriter::counters(std::size_t axis) const {
  const Counts& n = counts_[axis];
  return {axes_[axis].ring->counts(), n.written.load(std::memory_order_relaxed),
          n.failed.load(std::memory_order_relaxed), n.deleted.load(std::memory_order_relaxed),
          n.bytes.load(std::memory_order_relaxed)};
}

std::string CaptureWriter::last_file() const {
  std::lock_guard lock(mutex_);
  return last_file_;
}

}  // namespace hsa::daemon
