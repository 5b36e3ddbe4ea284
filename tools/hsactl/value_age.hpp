// How old the values hsactl shows are, and its words for a value that is not live: hsad keeps the
// last number of an input it no longer reads (a driver in error), so a value is shown with its age,
// and as STALE when hsad marked it so (msgs/README.md, Age of values).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "hsa/status_t.hpp"
#include "hsa/telemetry_t.hpp"

namespace hsa::ctl {

struct ValueAge {
  std::int64_t age_us = -1;  // −1: the axis has no such input
  bool stale = false;
};

// The status's rod position (status_t.position_m) as of the status's own time: its age at the
// sample (position_age_us) plus the time from the sample to the status, so that a sample that
// stopped coming ages too.
[[nodiscard]] ValueAge status_position_age(const hsa::status_t& s);

// The inputs of a telemetry sample in telemetry_t's order: their JSON key, their name in text,
// their age and stale mark.
struct InputAgeView {
  const char* key;   // "pressure_a"
  const char* name;  // "pressure A"
  ValueAge age;
};
[[nodiscard]] std::array<InputAgeView, 5> telemetry_inputs(const hsa::telemetry_t& t);

// "0.4 ms old", "2.310 s old", "STALE, 2.310 s old"; "no such input" for age −1.
[[nodiscard]] std::string age_text(const ValueAge& a);

// The bound inputs of a sample, one after the other: "position 0.1 ms old, pressure A STALE, ...".
[[nodiscard]] std::string inputs_text(const hsa::telemetry_t& t);

}  // namespace hsa::ctl
