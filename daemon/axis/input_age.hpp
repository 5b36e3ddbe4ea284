// How old the value of one input is, as status and telemetry carry it with every value read from a
// device: a value hsad no longer reads (a driver in error, a frozen channel, a silent bus) keeps
// its last number, and only its age tells an operator that it is not the rod of now.
//
// Computed on the RT thread from numbers it already holds (the cycle time and the sample's
// timestamp, both on the daemon's clock): no clock read, no text. The operator's words for it are
// hsactl's.
#pragma once

#include <algorithm>
#include <cstdint>

namespace hsa::daemon {

struct InputAge {
  std::int64_t age_ns = -1;  // cycle time − the sample's timestamp; -1: the axis has no such input
  bool stale = false;        // not live: the sample is not ok, or older than the axis's threshold
};

// `stale_after_ns` is the axis's input_stale threshold, the age past which the supervisor faults a
// judged input: a value older than that is not live, whatever the supervisor makes of it (it does
// not judge ages while a driver is in error). A timestamp ahead of the cycle (a device clock that
// ran ahead) counts as age 0.
template <class Sample>
constexpr InputAge input_age(const Sample& sample, std::int64_t t_ns, std::int64_t stale_after_ns) noexcept {
  const std::int64_t age = std::max<std::int64_t>(0, t_ns - sample.timestamp.count());
  return {age, !sample.ok() || age > stale_after_ns};
}

}  // namespace hsa::daemon
