// The "gpiod" driver plugin: digital inputs and outputs on GPIO lines of the Linux GPIO character
// device, through libgpiod 1.6. Settings: see drivers/gpiod/gpiod_settings.hpp.
//
// Lifecycle. on_configure parses the settings and requests every line with the consumer "hsad"
// (GpioLines): outputs are driven at their safe value from that moment. A missing chip or line,
// or a line another program holds, fails here with a message naming the key, the chip, the line
// and the holder. on_activate restarts the charge pumps from their safe level: write() drives the
// outputs from the next cycle. on_deactivate drives every output to its safe value. on_cleanup
// releases the lines. on_error drives the outputs (charge pumps included) to their safe values
// before it releases the lines: the kernel keeps a released output at its last level, so a failed
// driver must not leave it at the last command, and the relay drops whatever the failure was.
//
// make_safe (RT thread) sets every output to its safe value (one ioctl each) and latches: write()
// changes no line until the next on_activate.
//
// Cycle. read() reads each input's level (one ioctl). Inputs with edge_events also drain their
// non-blocking event fd and go through an EdgeLatch, so a pulse between two cycles shows for one
// cycle. write() sets each output (one ioctl). No allocation, lock or blocking call: a GPIO ioctl
// returns at once. A failed call marks the channel disconnected and returns IoStatus::error (a
// GPIO line does not fail transiently: the chip was unplugged or unbound).
//
// Charge pumps (charge_pump = true, charge_pump.hpp): write() toggles the line itself, every
// divisor-th call, while the driver is active and the pump enabled; the slot value is ignored.
// The enable is the outputs the channel's enabled_by names, as this same write() sets them: with
// any of them off the pump goes to its safe level in this write(). hsad writes an axis's valve
// enable off in the very cycle the axis leaves ENABLED (FAULT, ESTOP, DISABLED; INIT never drives),
// so a pump enabled by the valve enables stops in that cycle, stays stopped through a reset (which
// leaves the axis DISABLED) and toggles again only once an enable has the valves driven. The
// pumps are set after every other output, so a line the relay watches never shows a wave with its
// enable already off. on_deactivate and on_error put it back at its safe level, so the square wave
// also stops whenever the RT thread does not run write() or the driver leaves the active state.
//
// Values are logical: active_low is applied by the kernel, so 1 means "active" on the wire's
// configured sense. Sample timestamps are the cycle time t: a GPIO read is instantaneous.
#include <algorithm>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/driver.hpp"
#include "drivers/gpiod/charge_pump.hpp"
#include "drivers/gpiod/edge_latch.hpp"
#include "drivers/gpiod/gpio_lines.hpp"
#include "drivers/gpiod/gpiod_settings.hpp"
#include "drivers/plugin_abi.hpp"

namespace hsa::io::gpiod {
namespace {

// "gpiochip3" for "3", "/dev/gpiochip3" and "gpiochip3" (gpiod_chip_open_lookup's spellings of
// one chip); anything else (a label) as given.
std::string chip_device_name(const std::string& chip) {
  const bool number = !chip.empty() && std::all_of(chip.begin(), chip.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (number) return "gpiochip" + chip;
  constexpr std::string_view dev = "/dev/";
  if (chip.starts_with(dev)) return chip.substr(dev.size());
  return chip;
}

class GpiodDriver final : public Driver {
 public:
  // The settings alone: no chip is opened and no line requested.
  Result check_settings(const toml::table& table) const override {
    return Result::of([&] { (void)parse_gpiod_settings(table); });
  }

  // Each chip once, by the name its character device has when the settings name it by number,
  // path or name; a label stays a label (only opening the chips would tell which it is).
  Result plan(const toml::table& table, DriverPlan& plan) const override {
    return Result::of([&] {
      const GpiodSettings settings = parse_gpiod_settings(table);
      plan.devices.clear();
      plan.channels.clear();
      for (const LineChannel& c : settings.channels) {
        const std::string device = "gpiochip:" + chip_device_name(c.address.chip);
        if (std::find(plan.devices.begin(), plan.devices.end(), device) == plan.devices.end()) {
          plan.devices.push_back(device);
        }
        plan.channels.push_back(c.info);
      }
    });
  }

  Result on_configure(const toml::table& table) override {
    try {
      GpiodSettings settings = parse_gpiod_settings(table);
      auto lines = std::make_unique<GpioLines>(settings.channels);
      std::vector<EdgeLatch> latches(settings.channels.size());
      std::vector<ChargePump> pumps;
      for (const LineChannel& c : settings.channels) pumps.emplace_back(c.divisor, c.safe_value);
      for (std::size_t i = 0; i < settings.channels.size(); ++i) {
        const LineChannel& c = settings.channels[i];
        if (!c.edge_events) continue;
        // Start the latch from the level now, and forget edges from before configure.
        const int level = lines->value(i);
        if (level < 0 || lines->drain_edges(i) < 0) {
          throw std::runtime_error(c.address.line_key + ": cannot read " + lines->describe(i));
        }
        latches[i].reset(level != 0);
      }
      maps_ = std::move(settings.channels);
      channels_.clear();
      for (const LineChannel& c : maps_) channels_.push_back(c.info);
      latches_ = std::move(latches);
      pumps_ = std::move(pumps);
      lines_ = std::move(lines);
    } catch (const std::exception& e) {  // every message names its key
      release();
      return Result::failure(e.what());
    }
    return Result::success();
  }

  std::span<const ChannelInfo> channels() const override { return channels_; }

  Result on_activate() override {
    for (ChargePump& p : pumps_) (void)p.stop();  // each pump starts its wave from the safe level
    safe_latched_ = false;
    return Result::success();
  }

  Result on_deactivate() override {
    std::string failed;
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (maps_[i].info.kind != ChannelKind::digital_output) continue;
      (void)pumps_[i].stop();
      if (lines_->set(i, maps_[i].safe_value) != 0) {
        failed += (failed.empty() ? "" : "; ") + lines_->describe(i) + " (" + maps_[i].info.name + ")";
      }
    }
    if (!failed.empty()) return Result::failure("outputs not set to their safe values: " + failed);
    return Result::success();
  }

  Result on_cleanup() override {
    release();
    return Result::success();
  }

  Result on_error() override {
    if (lines_) set_safe_levels();  // best effort: a line of an unplugged chip cannot be set
    return on_cleanup();
  }

  void make_safe() noexcept override {
    safe_latched_ = true;
    if (lines_) set_safe_levels();
  }

  IoStatus read(Timestamp t, Duration, std::span<ChannelSlot> slots) noexcept override {
    IoStatus status = IoStatus::ok;
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      const LineChannel& c = maps_[i];
      if (c.info.kind != ChannelKind::digital_input) continue;
      const int level = lines_->value(i);  // level first, then the edges: see edge_latch.hpp
      const int edges = c.edge_events && level >= 0 ? lines_->drain_edges(i) : 0;
      if (level < 0 || edges < 0) {
        slots[i] = {slots[i].value, t, SampleStatus::disconnected};
        status = IoStatus::error;
        continue;
      }
      const bool value =
          c.edge_events ? latches_[i].update(level != 0, static_cast<unsigned int>(edges)) : level != 0;
      slots[i] = {value ? 1.0 : 0.0, t, SampleStatus::ok};
    }
    return status;
  }

  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot> slots) noexcept override {
    if (safe_latched_) return IoStatus::ok;
    IoStatus status = IoStatus::ok;
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (maps_[i].info.kind != ChannelKind::digital_output || maps_[i].charge_pump) continue;
      if (lines_->set(i, on(slots[i])) != 0) status = IoStatus::error;
    }
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (!maps_[i].charge_pump) continue;
      const bool enabled = std::all_of(maps_[i].enabled_by.begin(), maps_[i].enabled_by.end(),
                                       [&](std::size_t j) { return on(slots[j]); });
      if (lines_->set(i, pumps_[i].step(enabled)) != 0) status = IoStatus::error;
    }
    return status;
  }

 private:
  static bool on(const ChannelSlot& slot) noexcept { return slot.value > 0.5; }

  void set_safe_levels() noexcept {
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (maps_[i].info.kind != ChannelKind::digital_output) continue;
      (void)lines_->set(i, maps_[i].charge_pump ? pumps_[i].stop() : maps_[i].safe_value);
    }
  }

  void release() {
    lines_.reset();  // releases the lines: the kernel keeps an output at its last value
    maps_.clear();
    channels_.clear();
    latches_.clear();
    pumps_.clear();
  }

  std::unique_ptr<GpioLines> lines_;
  std::vector<LineChannel> maps_;  // the configured channels, indexed like their slots
  std::vector<ChannelInfo> channels_;
  std::vector<EdgeLatch> latches_;  // used by the edge_events inputs only
  std::vector<ChargePump> pumps_;   // indexed like the channels; used by the charge pumps only
  bool safe_latched_ = false;       // make_safe ran: outputs stay safe until on_activate
};

}  // namespace
}  // namespace hsa::io::gpiod

HSA_DRIVER_PLUGIN("gpiod", hsa::io::gpiod::GpiodDriver)
