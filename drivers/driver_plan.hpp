// What a driver's settings make it open and declare, found from the settings alone.
//
// hsad needs both before it opens anything: the devices to lock them, so that a second hsad on the
// same device is refused however its settings spell it (daemon/hsad/instance_lock.hpp), and the
// channels so that `hsad --check-config` binds the axes' signals as the start would and refuses
// what the start would refuse. Only the plugin knows its settings' keys and defaults, so the
// plugin states both (Driver::plan).
#pragma once

#include <string>
#include <vector>

#include "drivers/channel.hpp"

namespace hsa::io {

struct DriverPlan {
  // One key per device the driver opens, the same for every spelling of that device in the
  // settings (the plugin's defaults applied, paths resolved), led by its kind:
  // "modbus-tcp:10.0.0.5:502", "serial:/dev/ttyUSB0", "can:can0", "gpiochip:gpiochip0". Empty for
  // a driver that opens no device (the simulated rig).
  std::vector<std::string> devices;
  // The channels on_configure would declare with these settings, in the same order.
  std::vector<ChannelInfo> channels;
};

}  // namespace hsa::io
