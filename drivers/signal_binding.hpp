// Signals bound to driver channels, with the limits and inversion the framework applies so that no
// driver has to. A channel is already in SI units: the driver scales its raw counts with the one
// convention of docs/drivers.md ("Scaling: one convention"), value = raw·scale + offset, so a signal
// does not scale again.
//   analog (and encoder) input  value = the channel's value; outside [low_limit, high_limit] the
//                               sample's status becomes out_of_range
//   analog output               the channel gets clamp(value, low_limit, high_limit), or 0 when
//                               !enable; clamping sets `saturated`
//   digital input               value = raw != invert    (LinuxCNC's in_not, as a parameter)
//   digital output              raw = value != invert
//
// Binding happens at configure time and throws BindingError on any mismatch, naming the signal,
// the driver and the channel: a wrong configuration stops the daemon before the first cycle.
// A bound signal holds a pointer to its slot in the driver's buffer; it is valid while the driver
// stays configured. Reading and writing a bound signal is real-time safe.
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <span>
#include <string_view>

#include "drivers/channel.hpp"
#include "drivers/driver_handle.hpp"
#include "drivers/signal.hpp"

namespace hsa::io {

inline constexpr double unlimited = std::numeric_limits<double>::infinity();

struct AnalogInputParams {
  double low_limit = -unlimited;
  double high_limit = unlimited;
};

struct AnalogOutputParams {
  double low_limit = -unlimited;
  double high_limit = unlimited;
  bool enable = true;
};

struct DigitalInputParams {
  bool invert = false;
};

struct DigitalOutputParams {
  bool invert = false;
};

// An encoder or analog input.
class AnalogInput {
 public:
  AnalogInput(const ChannelSlot& slot, const AnalogInputParams& params)
      : slot_(&slot), params_(params) {}

  [[nodiscard]] AnalogSample sample() const noexcept;
  [[nodiscard]] const AnalogInputParams& params() const { return params_; }

 private:
  const ChannelSlot* slot_;
  AnalogInputParams params_;
};

class AnalogOutput {
 public:
  AnalogOutput(ChannelSlot& slot, const AnalogOutputParams& params);

  // Stores the raw value for the next write(). A non-finite request outputs 0 and reports
  // saturated, so that a NaN from upstream never reaches a valve.
  AnalogOutputState set(double value) noexcept;
  // LinuxCNC's `enable` pin: false outputs 0 from the next set() on.
  void set_enable(bool enable) noexcept { params_.enable = enable; }

  [[nodiscard]] AnalogOutputState state() const { return state_; }
  [[nodiscard]] const AnalogOutputParams& params() const { return params_; }

 private:
  ChannelSlot* slot_;
  AnalogOutputParams params_;
  AnalogOutputState state_{};
};

class DigitalInput {
 public:
  DigitalInput(const ChannelSlot& slot, const DigitalInputParams& params)
      : slot_(&slot), params_(params) {}

  [[nodiscard]] DigitalSample sample() const noexcept;

 private:
  const ChannelSlot* slot_;
  DigitalInputParams params_;
};

class DigitalOutput {
 public:
  DigitalOutput(ChannelSlot& slot, const DigitalOutputParams& params);

  void set(bool value) noexcept;
  [[nodiscard]] bool value() const { return value_; }

 private:
  ChannelSlot* slot_;
  DigitalOutputParams params_;
  bool value_ = false;
};

class BindingError : public std::runtime_error {
 public:
  BindingError(std::string signal, std::string driver, std::string channel,
               const std::string& message)
      : std::runtime_error(message),
        signal_(std::move(signal)),
        driver_(std::move(driver)),
        channel_(std::move(channel)) {}

  [[nodiscard]] const std::string& signal() const { return signal_; }
  [[nodiscard]] const std::string& driver() const { return driver_; }
  [[nodiscard]] const std::string& channel() const { return channel_; }

 private:
  std::string signal_;
  std::string driver_;
  std::string channel_;
};

// What a binding is checked against: a driver's instance name, its plugin's name and the channels
// it declares: a configured DriverHandle's, or those its settings state (Driver::plan), for
// `hsad --check-config`, which opens no device.
struct DeclaredDriver {
  std::string_view name;
  std::string_view plugin;
  std::span<const ChannelInfo> channels;
};

// The checks the bind_* functions make, without binding: `driver` declares `channel`, of the kind
// `wanted`; for an analog signal (`limits` given), low_limit <= high_limit. Returns the channel's
// index; throws the BindingError the bind would throw, with the same text.
std::size_t check_binding(std::string_view signal, const DeclaredDriver& driver, std::string_view channel,
                          ChannelKind wanted, const double* low_limit = nullptr, const double* high_limit = nullptr);

// Each checks that `driver` is configured, declares `channel`, that the channel has the kind the
// signal needs, and that the parameters make sense (check_binding); then returns the bound signal.
AnalogInput bind_encoder_input(std::string_view signal, DriverHandle& driver,
                               std::string_view channel, const AnalogInputParams& params = {});
AnalogInput bind_analog_input(std::string_view signal, DriverHandle& driver,
                              std::string_view channel, const AnalogInputParams& params = {});
AnalogOutput bind_analog_output(std::string_view signal, DriverHandle& driver,
                                std::string_view channel, const AnalogOutputParams& params = {});
DigitalInput bind_digital_input(std::string_view signal, DriverHandle& driver,
                                std::string_view channel, const DigitalInputParams& params = {});
DigitalOutput bind_digital_output(std::string_view signal, DriverHandle& driver,
                                  std::string_view channel,
                                  const DigitalOutputParams& params = {});

}  // namespace hsa::io
