// What the control code sees of the I/O: samples of named signals in SI units.
//
// A signal is the control side of a driver channel (see signal_binding.hpp for how the two are
// joined). Inputs carry a timestamp and a status with every value, so that a frozen or missing
// sensor is visible where the value is used; outputs report whether the framework had to clamp.
// Encoder and analog inputs share one sample type: both are a number in SI units.
#pragma once

#include "drivers/clock.hpp"
#include "drivers/sample_status.hpp"

namespace hsa::io {

// Encoder or analog input: rod position (m), pressure (Pa), spool position (m), current (A).
struct AnalogSample {
  double value = 0.0;
  Timestamp timestamp{};
  SampleStatus status = SampleStatus::disconnected;

  [[nodiscard]] bool ok() const { return status == SampleStatus::ok; }
};

// Digital input, after inversion: true means "asserted" (e-stop pressed, limit reached, ...).
struct DigitalSample {
  bool value = false;
  Timestamp timestamp{};
  SampleStatus status = SampleStatus::disconnected;

  [[nodiscard]] bool ok() const { return status == SampleStatus::ok; }
};

// What an analog output actually commands, in the signal's units: 0 when disabled, the clamped
// value when the request was outside the limits (then `saturated` is set, so that an integrator
// upstream can stop winding up).
struct AnalogOutputState {
  double value = 0.0;
  bool saturated = false;
};

}  // namespace hsa::io
