// Faults a test can inject into the simulated rig while it runs. They model what goes wrong on a
// real rig: a sensor that freezes, a broken cable, a noisy ground, a seized spool, a pump trip.
#pragma once

namespace hsa::sim {

enum class SensorFaultMode {
  none,
  stuck,         // the reading freezes at the value it had when the fault was set
  disconnected,  // the channel reports no signal (SensorReading::connected == false)
};

struct SensorFault {
  SensorFaultMode mode = SensorFaultMode::none;
  double extra_noise_std = 0.0;  // added white noise, in the sensor's SI unit
};

struct FaultInjection {
  SensorFault encoder;
  SensorFault pressure_a;
  SensorFault pressure_b;
  SensorFault spool_lvdt;
  SensorFault valve_current;
  bool valve_stuck = false;  // the spool (or servo-valve opening) freezes where it is
  bool supply_lost = false;  // the pump stops: no flow from the supply port
};

}  // namespace hsa::sim
