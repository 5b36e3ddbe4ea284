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

DeclaredDriver declared(const DriverHandle& driver) {
  return {driver.name(), driver.plugin().descriptor().name, driver.channels()};
}

std::string describe(std::string_view signal, const DeclaredDriver& driver, std::string_view channel) {
  return "signal '" + std::string(signal) + "' bound to driver '" + std::string(driver.name) + "' (plugin " +
         std::string(driver.plugin) + "), channel '" + std::string(channel) + "'";
}

[[noreturn]] void fail(std::string_view signal, const DeclaredDriver& driver, std::string_view channel,
                       const std::string& why) {
  throw BindingError(std::string(signal), std::string(driver.name), std::string(channel),
                     describe(signal, driver, channel) + ": " + why);
}

ChannelSlot& find_slot(std::string_view signal, DriverHandle& driver, std::string_view channel, ChannelKind wanted,
                       const double* low_limit = nullptr, const double* high_limit = nullptr) {
  const DriverState state = driver.state();
  if (state != DriverState::inactive && state != DriverState::active) {
    fail(signal, declared(driver), channel, "the driver is " + std::string(to_string(state)) + ", not configured");
  }
  return driver.slots()[check_binding(signal, declared(driver), channel, wanted, low_limit, high_limit)];
}

AnalogInput bind_input(std::string_view signal, DriverHandle& driver, std::string_view channel,
                       const AnalogInputParams& params, ChannelKind kind) {
  return AnalogInput(find_slot(signal, driver, channel, kind, &params.low_limit, &params.high_limit), params);
}

}  // namespace

std::size_t check_binding(std::string_view signal, const DeclaredDriver& driver, std::string_view channel,
                          ChannelKind wanted, const double* low_limit, const double* high_limit) {
  const auto info = std::find_if(driver.channels.begin(), driver.channels.end(),
                                 [&](const ChannelInfo& c) { return c.name == channel; });
  if (info == driver.channels.end()) {
    std::string known;
    for (const auto& c : driver.channels) known += (known.empty() ? "" : ", ") + c.name;
    fail(signal, driver, channel, "no such channel (the driver has: " + known + ")");
  }
  if (info->kind != wanted) {
    fail(signal, driver, channel,
         "kind mismatch: the signal is " + std::string(to_string(wanted)) + ", the channel is " +
             std::string(to_string(info->kind)) + " (" + info->unit + ")");
  }
  if (low_limit != nullptr && high_limit != nullptr && !(*low_limit <= *high_limit)) {
    fail(signal, driver, channel,
         "low_limit (" + std::to_string(*low_limit) + ") is above high_limit (" + std::to_string(*high_limit) + ")");
  }
  return static_cast<std::size_t>(info - driver.channels.begin());
}

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
  return AnalogOutput(
      find_slot(signal, driver, channel, ChannelKind::analog_output, &params.low_limit, &params.high_limit), params);
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
