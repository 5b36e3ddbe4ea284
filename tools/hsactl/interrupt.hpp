// Set by hsactl's SIGINT and SIGTERM handler: a command that streams (open, move, sine, watch,
// record) stops at its next step, and hsactl exits 130.
#pragma once

#include <atomic>

namespace hsa::ctl {

inline std::atomic<bool> interrupted{false};

}  // namespace hsa::ctl
