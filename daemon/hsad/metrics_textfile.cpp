#include "daemon/hsad/metrics_textfile.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <utility>

namespace hsa::daemon {

MetricsTextfile::MetricsTextfile(std::string path) : path_(std::move(path)) {}

MetricsTextfile::~MetricsTextfile() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void MetricsTextfile::start() { thread_ = std::thread([this] { run(); }); }

void MetricsTextfile::post(MetricsSnapshot snapshot) {
  {
    const std::lock_guard lock(mutex_);
    pending_ = std::move(snapshot);
  }
  wake_.notify_one();
}

void MetricsTextfile::stop(const MetricsSnapshot& last) {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
    pending_.reset();
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  write(last);
}

void MetricsTextfile::run() {
  for (;;) {
    MetricsSnapshot snapshot;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_.has_value(); });
      if (stop_) return;
      snapshot = std::move(*pending_);
      pending_.reset();
    }
    write(snapshot);
  }
}

void MetricsTextfile::write(const MetricsSnapshot& snapshot) {
  std::string error;
  try {
    error = write_atomically(path_, metrics_text(snapshot));
  } catch (const std::exception& e) {  // a bad metric name: a bug, but no reason to end hsad
    error = std::string("cannot format the metrics: ") + e.what();
  }
  if (error.empty()) {
    written_.fetch_add(1, std::memory_order_relaxed);
    if (!last_error_.empty()) std::fprintf(stderr, "hsad: metrics: writing %s again\n", path_.c_str());
    last_error_.clear();
    return;
  }
  failed_.fetch_add(1, std::memory_order_relaxed);
  if (error != last_error_) std::fprintf(stderr, "hsad: metrics: %s (the daemon runs on)\n", error.c_str());
  last_error_ = error;
}

std::string MetricsTextfile::write_atomically(const std::string& path, const std::string& text) {
  const std::string temp = path + ".tmp";
  auto failure = [&](const char* what, const std::string& file) {
    const std::string reason = std::strerror(errno);
    (void)unlink(temp.c_str());
    return std::string("cannot ") + what + " " + file + ": " + reason;
  };
  // 0644: the node exporter runs as its own user and only reads.
  const int fd = open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return std::string("cannot create ") + temp + ": " + std::strerror(errno);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string why = failure("write", temp);
      close(fd);
      return why;
    }
    done += static_cast<std::size_t>(n);
  }
  if (close(fd) != 0) return failure("write", temp);
  if (rename(temp.c_str(), path.c_str()) != 0) return failure("rename over", path);
  return {};
}

}  // namespace hsa::daemon
