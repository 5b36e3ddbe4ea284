// The flight recorder's tables, [recorder] and each axis's [axes.recorder], read with the located
// errors of the rest of the configuration (file, line, key path, what was expected).
#pragma once

#include "daemon/config/daemon_config.hpp"
#include "daemon/config/recorder_config.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

// `root` is the file's top-level table; a missing [recorder] gives the defaults.
RecorderConfig parse_recorder(const io::TableReader& root);
// `axis` is one [[axes]] table; a missing [axes.recorder] gives the defaults.
AxisRecorderConfig parse_axis_recorder(const io::TableReader& axis, const RealtimeConfig& rt);

}  // namespace hsa::daemon
