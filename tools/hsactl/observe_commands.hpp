// hsactl's commands that only look at the axis: its status (as text or JSON), a live view, and its
// telemetry as CSV, live or from an lcm-logger log.
#pragma once

#include <string>

#include "tools/hsactl/lcm_session.hpp"

namespace hsa::ctl {

int status(LcmSession& session, bool json);
// The PI gains in use and the gain changes applied and refused.
int print_gains(LcmSession& session);
// The axes that answer on the LCM URL, with their state.
int axes(LcmSession& session);
// Each driver of the axis: lifecycle state, link, counters, last error.
int drivers(LcmSession& session);
int watch(LcmSession& session, double duration_s);
int record(LcmSession& session, const std::string& path, double duration_s);
int log_to_csv(const std::string& log_path, const std::string& axis, const std::string& csv_path);

}  // namespace hsa::ctl
