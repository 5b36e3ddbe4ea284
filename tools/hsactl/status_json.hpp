// `hsactl status --json`: the axis's last status and, when one arrived, its last telemetry sample,
// as one JSON object. Field names are the status_t and telemetry_t fields a script needs (see
// docs/operation.md); fault reasons and other strings are escaped by the JSON library, and a value that is not
// a finite number (a disconnected sensor's NaN) is written as null, since JSON has no NaN (the
// library's rule when it writes a document). The telemetry fields are not authenticated
// (docs/security.md); status_position_m and status_setpoint_m are the rod as hsad's status has it.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::ctl {

// How far hsactl could trust the status: whether it verified it (it had a key), and how many
// status messages failed verification before it was printed.
struct StatusTrust {
  bool verified = false;
  std::uint64_t unverified_status = 0;
};

[[nodiscard]] nlohmann::ordered_json status_json(const std::string& axis, const hsa::status_t& status,
                                                 const hsa::telemetry_t* telemetry, const StatusTrust& trust);

}  // namespace hsa::ctl
