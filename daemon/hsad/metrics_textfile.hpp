// The Prometheus textfile of hsad's health (docs/monitoring.md): a normal thread, never the RT
// thread, that formats each snapshot the operator thread posts (metrics_text.hpp) and writes it
// atomically for the node exporter's textfile collector: into "<file>.tmp" in the same folder,
// then rename(2) over the file, so a scrape reads the whole previous file or the whole new one,
// never half of either (the collector reads only *.prom, so it never reads the .tmp).
//
// hsad serves no HTTP endpoint of its own: a listening socket in the process of a SCHED_FIFO
// daemon would let anyone who reaches the port make it format and send on demand, at the
// network's rate; the node exporter already runs on the lab's hosts and is scraped anyway. The
// file costs hsad one write per interval, whoever reads it how often.
//
// A file that cannot be written (a missing folder, a full disk) costs that snapshot, is counted
// and said on stderr once per new reason, and once more when writing works again; the daemon runs
// on. No fsync: the rename makes the file whole for readers, and after a crash the file is stale
// anyway (hsa_running and the collector's node_textfile_mtime_seconds say so).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "daemon/hsad/metrics_text.hpp"

namespace hsa::daemon {

class MetricsTextfile {
 public:
  explicit MetricsTextfile(std::string path);
  ~MetricsTextfile();
  MetricsTextfile(const MetricsTextfile&) = delete;
  MetricsTextfile& operator=(const MetricsTextfile&) = delete;

  void start();
  // Hands a snapshot to the writer thread; one it has not written yet is replaced (the newer
  // counts include the older ones).
  void post(MetricsSnapshot snapshot);
  // Ends the thread, then writes `last` on the caller's thread: the file hsad leaves behind.
  void stop(const MetricsSnapshot& last);

  // Writes `text` to `path` atomically (temp file and rename). Returns "" or why it could not.
  [[nodiscard]] static std::string write_atomically(const std::string& path, const std::string& text);

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t failed() const { return failed_.load(std::memory_order_relaxed); }

 private:
  void run();
  void write(const MetricsSnapshot& snapshot);

  const std::string path_;
  std::mutex mutex_;  // pending_ and stop_
  std::condition_variable wake_;
  std::optional<MetricsSnapshot> pending_;
  bool stop_ = false;
  std::string last_error_;  // writer thread, then stop()'s caller after the join
  std::atomic<std::uint64_t> written_{0}, failed_{0};
  std::thread thread_;
};

}  // namespace hsa::daemon
