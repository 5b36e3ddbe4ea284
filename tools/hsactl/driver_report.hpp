// The drivers of an axis as status carries them (status_t.drivers), in words for `hsactl drivers`
// and `hsactl status`, and as JSON for `hsactl status --json`.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "hsa/driver_status_t.hpp"

namespace hsa::ctl {

// "io (modbus): active, link up; link_errors 0, transaction_errors 3, output_timeouts 0", then
// "last error: ..." and "failure: ..." when there are any, each on its own line.
std::string driver_report(const hsa::driver_status_t& d);
nlohmann::ordered_json driver_json(const hsa::driver_status_t& d);

}  // namespace hsa::ctl
