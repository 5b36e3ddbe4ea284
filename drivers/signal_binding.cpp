#include "drivers/signal_binding.hpp"

#include <algorithm>
#include <cmath>

namespace hsa::io {

AnalogSample AnalogInput::sample() const noexcept {
  AnalogSample s{slot_->value, slot_->timestamp, slot_->status};
  // Written so that NaN, which compares false with everything, is out of range too.
  const bool in_range = s.value >= params_.low_limit && s.value <= params_.high_limit;
  if (s.status == SampleStatus::ok && !in_range) s.status = SampleStatus::out_of_range;
  return s;
}

AnalogOutput::AnalogOutput(ChannelSlot& slot, const AnalogOutputParams& params)
    : slot_(&slot), params_(params) {
  slot_->value = 0.0;  // nothing commanded yet
}

AnalogOutputState AnalogOutput::set(double value) noexcept {
  if (!params_.enable) {
    state_ = {0.0, false};
    slot_->value = 0.0;
  } else if (!std::isfinite(value)) {
    state_ = {0.0, true};
    slot_->value = 0.0;
  } else {
    const double clamped = std::clamp(value, params_.low_limit, params_.high_limit);
    state_ = {clamped, clamped != value};
    slot_->value = clamped;
  }
  return state_;
}

DigitalSample DigitalInput::sample() const noexcept {
  return {(slot_->value != 0.0) != params_.invert, slot_->timestamp, slot_->status};
}

DigitalOutput::DigitalOutput(ChannelSlot& slot, const DigitalOutputParams& params)
    : slot_(&slot), params_(params) {
  set(false);
}

void DigitalOutput::set(bool value) noexcept {
  value_ = value;
  slot_->value = (value != params_.invert) ? 1.0 : 0.0;
}

namespace {

std::string describe(std::string_view signal, const DriverHandle& driver,
                     std::string_view channel) {
  return "signal '" + std::string(signal) + "' bound to driver '" + driver.name() + "' (plugin " +
         driver.plugin().name() + "), channel '" + std::string(channel) + "'";
}

[[noreturn]] void fail(std::string_view signal, const DriverHandle& driver,
                       std::string_view channel, const std::string& why) {
  throw BindingError(std::string(signal), driver.name(), std::string(channel),
                     describe(signal, driver, channel) + ": " + why);
}

ChannelSlot& find_slot(std::string_view signal, DriverHandle& driver, std::string_view channel,
                       ChannelKind wanted) {
  const DriverState state = driver.state();
  if (state != DriverState::inactive && state != DriverState::active) {
    fail(signal, driver, channel,
         "the driver is " + std::string(to_string(state)) + ", not configured");
  }
  const auto index = driver.find_channel(channel);
  if (!index) {
    std::string known;
    for (const auto& c : driver.channels()) known += (known.empty() ? "" : ", ") + c.name;
    fail(signal, driver, channel, "no such channel (the driver has: " + known + ")");
  }
  const ChannelInfo& info = driver.channels()[*index];
  if (info.kind != wanted) {
    fail(signal, driver, channel,
         "kind mismatch: the signal is " + std::string(to_string(wanted)) + ", the channel is " +
             std::string(to_string(info.kind)) + " (" + info.unit + ")");
  }
  return driver.slots()[*index];
}

void check_limits(std::string_view signal, const DriverHandle& driver, std::string_view channel,
                  double low_limit, double high_limit) {
  if (!(low_limit <= high_limit)) {
    fail(signal, driver, channel,
         "low_limit (" + std::to_string(low_limit) + ") is above high_limit (" +
             std::to_string(high_limit) + ")");
  }
}

AnalogInput bind_input(std::string_view signal, DriverHandle& driver, std::string_view channel,
                       const AnalogInputParams& params, ChannelKind kind) {
  const ChannelSlot& slot = find_slot(signal, driver, channel, kind);
  check_limits(signal, driver, channel, params.low_limit, params.high_limit);
  return AnalogInput(slot, params);
}

}  // namespace

AnalogInput bind_encoder_input(std::string_view signal, DriverHandle& driver,
                               std::string_view channel, const AnalogInputParams& params) {
  return bind_input(signal, driver, channel, params, ChannelKind::encoder_input);
}

AnalogInput bind_analog_input(std::string_view signal, DriverHandle& driver,
                              std::string_view channel, const AnalogInputParams& params) {
  return bind_input(signal, driver, channel, params, ChannelKind::analog_input);
}

AnalogOutput bind_analog_output(std::string_view signal, DriverHandle& driver,
                                std::string_view channel, const AnalogOutputParams& params) {
  ChannelSlot& slot = find_slot(signal, driver, channel, ChannelKind::analog_output);
  check_limits(signal, driver, channel, params.low_limit, params.high_limit);
  return AnalogOutput(slot, params);
}

DigitalInput bind_digital_input(std::string_view signal, DriverHandle& driver,
                                std::string_view channel, const DigitalInputParams& params) {
  return DigitalInput(find_slot(signal, driver, channel, ChannelKind::digital_input), params);
}

DigitalOutput bind_digital_output(std::string_view signal, DriverHandle& driver,
                                  std::string_view channel, const DigitalOutputParams& params) {
  return DigitalOutput(find_slot(signal, driver, channel, ChannelKind::digital_output), params);
}

}  // namespace hsa::io
