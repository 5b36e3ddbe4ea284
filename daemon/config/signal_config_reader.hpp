// The [axes.signals] table of an axis: each signal bound to a configured driver and one of its
// channels, with the limits (analog) or inversion (digital) the binding applies. Scaling is the
// channel's (docs/drivers.md, "Scaling: one convention"), so a signal table that still has scale or offset
// is refused with where they went. Errors are the reader's: file, line, key path, expectation.
#pragma once

#include <vector>

#include "control/control_law.hpp"
#include "daemon/config/daemon_config.hpp"
#include "daemon/config/signal_config.hpp"
#include "drivers/table_reader.hpp"

namespace hsa::daemon {

// `law` says whether the axis needs a spool signal; `drivers` are the configured instances a
// signal may name.
AxisSignalConfig parse_signals(const io::TableReader& t, const control::ControlLaw& law,
                               const std::vector<DriverConfig>& drivers);

}  // namespace hsa::daemon
