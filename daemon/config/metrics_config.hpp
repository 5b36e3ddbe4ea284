// [metrics]: where hsad writes its health for the Prometheus node exporter's textfile collector,
// and how often (docs/monitoring.md). No [metrics] table: no file.
#pragma once

#include <string>

namespace hsa::daemon {

struct MetricsConfig {
  std::string textfile;    // absolute path ending in ".prom"; "" = no metrics
  double interval_s = 5.0;  // seconds between two writes of the file

  [[nodiscard]] bool enabled() const { return !textfile.empty(); }
};

}  // namespace hsa::daemon
