// hsactl's commands that only look at the axis: its status (as text or JSON), a live view, and its
// telemetry as CSV, live or from an lcm-logger log.
#pragma once

#include <string>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

int status(LcmSession& session, bool json);
// Each driver of the axis: lifecycle state, link, counters, last error.
int drivers(LcmSession& session);
int watch(LcmSession& session, double duration_s);
int record(LcmSession& session, const std::string& path, double duration_s);
int log_to_csv(const std::string& log_path, const std::string& axis, const std::string& csv_path);

}  // namespace hsa::ctl
