#include "daemon/supervisor/axis_state.hpp"

namespace hsa::daemon {

std::string_view to_string(AxisState state) noexcept {
  switch (state) {
    case AxisState::init: return "INIT";
    case AxisState::disabled: return "DISABLED";
    case AxisState::enabled: return "ENABLED";
    case AxisState::fault: return "FAULT";
    case AxisState::estop: return "ESTOP";
  }
  return "?";
}

std::string_view to_string(ControlMode mode) noexcept {
  switch (mode) {
    case ControlMode::position: return "position";
    case ControlMode::open_loop: return "open_loop";
  }
  return "?";
}

}  // namespace hsa::daemon
