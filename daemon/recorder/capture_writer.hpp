// The flight recorder's writer: a normal (non-RT) thread that polls every axis's CaptureRing for a
// frozen capture, writes it as a MAT-file into the folder (capture_file.hpp), gives the buffer
// back, and keeps the folder within its bounds (capture_folder.hpp).
//
// Polling, every 20 ms, because the RT thread may not wake anybody (a futex or eventfd write is a
// system call); a capture waits at most that long, far less than the post-trigger time a second
// capture needs. A folder that cannot be written (missing, read-only, full) costs the capture, is
// counted (failed) and logged on stderr with the reason, and never reaches the RT thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "daemon/recorder/capture_file.hpp"
#include "daemon/recorder/capture_folder.hpp"
#include "daemon/recorder/capture_ring.hpp"

namespace hsa::daemon {

struct RecorderCounters {
  CaptureRingCounts ring;       // the RT side (capture_ring.hpp)
  std::uint64_t written = 0;    // files written
  std::uint64_t failed = 0;     // captures that could not be written
  std::uint64_t deleted = 0;    // old captures deleted to keep the folder's bounds
  std::uint64_t bytes = 0;      // bytes written
};

class CaptureWriter {
 public:
  struct Axis {
    CaptureRing* ring;
    CaptureContext context;
  };
  CaptureWriter(std::filesystem::path folder, CaptureFolderLimits limits, std::vector<Axis> axes);
  ~CaptureWriter();
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  void start();
  // Writes what is frozen now, then ends the thread.
  void stop();
  // Writes what is frozen now, on the caller's thread (the thread's own work, for tests and stop).
  void poll();

  [[nodiscard]] RecorderCounters counters(std::size_t axis) const;
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  // The last file written (any axis), "" before the first.
  [[nodiscard]] std::string last_file() const;

 private:
  struct Counts {
    std::atomic<std::uint64_t> written{0}, failed{0}, deleted{0}, bytes{0};
  };
  void write(std::size_t index, const Capture& capture);

  const std::filesystem::path folder_;
  const CaptureFolderLimits limits_;
  std::vector<Axis> axes_;
  std::vector<Counts> counts_;
  mutable std::mutex mutex_;  // last_file_ and stop_
  std::mutex writing_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::string last_file_;
  std::thread thread_;
};

}  // namespace hsa::daemon
