// What a driver knows of its link to the device, for the daemon's status and `hsactl drivers`.
//
// A driver with a bus (Modbus, CAN) says whether the link is up, the last error the link gave
// (libmodbus's or the socket's errno text), and its error counters; a driver without one (the
// simulated rig, local GPIO lines) says nothing. Taken by the operator thread at the status rate,
// so it may allocate; a driver keeps what it reports in atomics its own threads update, so asking
// never waits for the bus or the RT thread.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hsa::io {

struct DriverHealth {
  // none: no link to speak of. not_answering: connected, or able to connect, but the device let
  // its last request time out (a hung or stopped device), as opposed to down: the connection
  // failed, was refused or reset.
  enum class Link : std::uint8_t { none, up, down, not_answering };
  Link link = Link::none;
  std::string last_error;  // the link's last error; empty when it has had none
  std::vector<std::pair<std::string, std::uint64_t>> counters;  // e.g. {"link_errors", 2}
};

// "none", "up", "down", "not answering": the link's state as status and logs word it.
constexpr std::string_view to_string(DriverHealth::Link link) noexcept {
  switch (link) {
    case DriverHealth::Link::none: return "none";
    case DriverHealth::Link::up: return "up";
    case DriverHealth::Link::down: return "down";
    case DriverHealth::Link::not_answering: return "not answering";
  }
  return "?";
}

}  // namespace hsa::io
