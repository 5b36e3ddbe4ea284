// The [metrics] table, read with the located errors of the rest of the configuration (file, line,
// key path, what was expected).
#pragma once

#include "daemon/config/metrics_config.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

// `root` is the file's top-level table; a missing [metrics] gives no metrics.
MetricsConfig parse_metrics(const io::TableReader& root);

}  // namespace hsa::daemon
