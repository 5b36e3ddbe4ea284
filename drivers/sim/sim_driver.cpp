// The "sim" driver plugin: the simulated rig of sim/rig.hpp behind the same channels a real rig
// wires to its I/O boards, so the daemon runs unchanged against the model or the hardware.
//
// Channels (raw values in SI units; scaling belongs to the signal bindings):
//   encoder        encoder input   m    rod position
//   pressure_a     analog input    Pa   chamber A
//   pressure_b     analog input    Pa   chamber B
//   spool_lvdt     analog input    m    spool position      } proportional valve only: a
//   valve_current  analog input    A    solenoid current    } servo-valve has its own electronics
//   current_ref    analog output   A    solenoid current reference (proportional valve)
//   opening_cmd    analog output   1    normalized opening in [-1, 1] (servo-valve)
//   valve_enable   digital output       valve amplifier enable
//   estop          digital input        e-stop loop, active low as wired: 1 = closed = not pressed
// A disconnected sensor (sim::SensorReading::connected == false) reads as status disconnected.
//
// Settings (all optional):
//   valve = "servo" | "proportional"   load_kg, initial_position_m, seed, step_s, and the rig's
//                        physical parameters in [rig] (rig_settings.hpp: the papers' rig by default)
//   timing = "cycle"     each read(t, dt) advances the rig by dt, in whole steps of step_s; the
//                        remainder carries to the next cycle so the model keeps pace with the daemon
//          | "lockstep"  each read advances exactly one step, whatever dt: deterministic tests
//          | "device"    the rig runs on its own clock, in the plugin's device thread, every step_s
//                        (device_clock.hpp): the RT thread's read takes the latest readings and
//                        its write leaves the command for the next step, as with a bus device, so
//                        the model's cost is not the daemon's. No [[events]] (the scenario would
//                        race the device). device_priority = 1..99 runs that thread SCHED_FIFO,
//                        device_cpu = N pins it; every device-timed rig of a process shares the
//                        thread, so they must agree on step_s and on these.
//   [[events]]           a scripted scenario in simulated time, because the daemon's end-to-end
//                        tests can reach the rig only through its configuration:
//     at_s = 0.5  and any of  estop = true | load_kg = 80 | valve_stuck = true |
//                             supply_lost = true | sensor = "pressure_a" + fault = "disconnected"
//   and the faults of the I/O path itself, which a real rig shows through its boards and buses:
//     encoder_jump_m = 0.01   the encoder reads that much more from now on (lost or extra counts)
//     encoder_stale = true    the encoder channel stops updating: its value and timestamp stay
//                             those of the last fresh sample (false: fresh samples again)
//     driver_error = true     read() and write() return IoStatus::error, as a bus that stopped
//                             answering (false: they succeed again; a DriverHandle that saw the
//                             error has stopped calling them until it is recovered). With
//                             driver_error_s = 3 the bus comes back 3 s later on the daemon's
//                             clock (the timestamps read() is given), so a recovery before then
//                             fails again and one after it succeeds.
//     stall_us = 500 + stall_cycles = 200
//                             the next 200 read() calls each busy-wait 500 µs on CLOCK_MONOTONIC
//                             before returning: a driver that overruns the RT period, the way a
//                             slow bus transfer does. Fault injection for tests of the daemon's
//                             overrun supervision only; nothing stalls unless an event says so.
//
// A lost bus is not a lost rig. on_error, the first step of a recovery, keeps the rig, its scenario
// and the state of the injected faults; the valve amplifier's own watchdog switches the valve off,
// as real valve electronics do when their bus goes quiet. An on_configure that follows with the
// same settings picks the rig up where it was; on_cleanup, or other settings, build it anew. The
// rig's simulated time stands still while no one reads it (the valve is off, so the rod holds).
//
// read/write allocate nothing: the rig is built in on_configure and its step() does not allocate;
// events are parsed into a sorted array there too. They take no lock and block only in an
// explicit stall event.
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/clock.hpp"
#include "drivers/driver.hpp"
#include "drivers/plugin_abi.hpp"
#include "drivers/sim/device_clock.hpp"
#include "drivers/sim/device_rig.hpp"
#include "drivers/sim/rig_settings.hpp"
#include "drivers/sim/scenario_event.hpp"
#include "drivers/table_reader.hpp"
#include "sim/faults.hpp"
#include "sim/rig.hpp"

namespace hsa::io::sim_plugin {
namespace {

enum class Timing { cycle, lockstep, device };

sim::SensorFault& fault_of(sim::FaultInjection& faults, Sensor sensor) {
  switch (sensor) {
    case Sensor::encoder: return faults.encoder;
    case Sensor::pressure_a: return faults.pressure_a;
    case Sensor::pressure_b: return faults.pressure_b;
    case Sensor::spool_lvdt: return faults.spool_lvdt;
    case Sensor::valve_current: return faults.valve_current;
  }
  return faults.encoder;
}

class SimDriver final : public Driver {
 public:
  SimDriver() = default;
  ~SimDriver() override { detach_device(); }

  // The rig is a model with no device behind it: configuring a scratch driver is the check (a
  // scratch rig never joins the device thread).
  Result check_settings(const toml::table& table) const override {
    SimDriver scratch(Scratch{});
    return scratch.on_configure(table);
  }

  // A model in this process: no device to lock.
  Result plan(const toml::table& table, DriverPlan& plan) const override {
    SimDriver scratch(Scratch{});
    Result r = scratch.on_configure(table);
    if (r) {
      plan.devices.clear();
      const auto channels = scratch.channels();
      plan.channels.assign(channels.begin(), channels.end());
    }
    return r;
  }

  Result on_configure(const toml::table& table) override {
    if (rig_kept_ && table == settings_) {  // a recovery: the same rig, where it was
      rig_kept_ = false;
      return Result::success();
    }
    rig_kept_ = false;
    try {
      configure(table);
    } catch (const std::exception& e) {  // ConfigError, or the rig refusing its RigConfig
      detach_device();
      rig_.reset();
      channels_.clear();
      return Result::failure(e.what());
    }
    return Result::success();
  }

  std::span<const ChannelInfo> channels() const override { return channels_; }

  Result on_activate() override {
    active_ = true;
    return Result::success();
  }

  Result on_deactivate() override {
    active_ = false;
    make_outputs_safe();
    return Result::success();
  }

  Result on_cleanup() override {
    detach_device();
    rig_.reset();
    rig_kept_ = false;
    channels_.clear();
    events_.clear();
    return Result::success();
  }

  Result on_error() override {
    active_ = false;
    make_outputs_safe();  // the amplifier's watchdog: no bus, no valve
    rig_kept_ = rig_ != nullptr;
    return Result::success();
  }

  IoStatus read(Timestamp t, Duration dt, std::span<ChannelSlot> slots) noexcept override {
    if (timing_ != Timing::device) {  // a device steps on its own, and has no events
      std::int64_t steps = 1;
      if (timing_ == Timing::cycle) {
        if (dt < Duration::zero()) return IoStatus::error;
        pending_ += dt;
        steps = pending_ / step_;
        pending_ -= steps * step_;
      }
      for (std::int64_t i = 0; i < steps; ++i) {
        apply_due_events(t);
        rig_->step();
      }
      apply_due_events(t);  // an e-stop due now shows in this cycle; sensor faults from the next step
    }
    if (driver_error_ && bus_back_at_ && t >= *bus_back_at_) {
      driver_error_ = false;
      bus_back_at_.reset();
    }
    if (stall_remaining_ > 0) {
      --stall_remaining_;
      const std::int64_t until = monotonic_ns() + stall_ns_;
      while (monotonic_ns() < until) {
      }
    }
    if (driver_error_) {
      make_outputs_safe();  // the amplifier's watchdog, as in on_error
      return IoStatus::error;  // the slots keep what the last good read left
    }

    const sim::RigReadings r = device_ ? device_->latest() : rig_->read();
    const auto put = [&](std::size_t index, const sim::SensorReading& reading) {
      slots[index] = {reading.value, t,
                      reading.connected ? SampleStatus::ok : SampleStatus::disconnected};
    };
    if (!encoder_stale_) {
      put(index_.encoder, r.encoder_m);
      slots[index_.encoder].value += encoder_offset_m_;
    }
    put(index_.pressure_a, r.pressure_a_pa);
    put(index_.pressure_b, r.pressure_b_pa);
    if (valve_ == sim::ValveKind::proportional) {
      put(index_.spool_lvdt, r.spool_lvdt_m);
      put(index_.valve_current, r.valve_current_a);
    }
    slots[index_.estop] = {r.estop_pressed ? 0.0 : 1.0, t, SampleStatus::ok};
    return IoStatus::ok;
  }

  // The valve off from the RT thread, until the next activation: write() no longer reaches the
  // rig, as an amplifier whose enable was dropped ignores its command.
  void make_safe() noexcept override {
    active_ = false;
    make_outputs_safe();
  }

  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot> slots) noexcept override {
    if (driver_error_) return IoStatus::error;
    if (!active_) return IoStatus::ok;
    const double command = slots[index_.command].value;
    const bool enable = slots[index_.enable].value != 0.0;
    if (device_) {
      device_->set_command(command);
      device_->set_enable(enable);
    } else {
      rig_->set_valve_command(command);
      rig_->set_valve_enable(enable);
    }
    return IoStatus::ok;
  }

 private:
  struct Scratch {};
  explicit SimDriver(Scratch) : scratch_(true) {}

  struct Indices {
    std::size_t encoder, pressure_a, pressure_b, spool_lvdt, valve_current, command, enable, estop;
  };

  void configure(const toml::table& table) {
    detach_device();  // the old rig leaves the device thread before it is replaced
    settings_ = table;
    const TableReader s = TableReader::of(table);
    std::vector<std::string_view> keys(kRigConfigKeys.begin(), kRigConfigKeys.end());
    keys.insert(keys.end(), {"timing", "events", "device_priority", "device_cpu"});
    s.reject_unknown_keys(keys);
    const sim::RigConfig config = read_rig_config(s);
    valve_ = config.valve;
    step_ = std::chrono::round<Duration>(std::chrono::duration<double>(config.step_s));
    if (step_ <= Duration::zero()) s.fail("step_s", "at least 1 ns");
    const std::string timing = s.choice("timing", {"cycle", "lockstep", "device"}, "cycle");
    timing_ = timing == "cycle" ? Timing::cycle : timing == "lockstep" ? Timing::lockstep : Timing::device;
    DeviceClockSettings device;
    device.step_ns = step_.count();
    if (timing_ == Timing::device) {
      device.priority = static_cast<int>(s.integer("device_priority", 0, 99, 0));
      device.cpu = static_cast<int>(s.integer("device_cpu", -1, CPU_SETSIZE - 1, -1));
      if (s.has("events")) s.fail("events", "no [[events]] with timing = \"device\" (the scenario runs in the rig's time, which the device thread owns)");
    } else {
      for (const char* key : {"device_priority", "device_cpu"})
        if (s.has(key)) s.fail(key, "only with timing = \"device\"");
    }
    events_.clear();
    for (const TableReader& t : s.tables("events")) events_.push_back(parse_event(t));
    std::stable_sort(events_.begin(), events_.end(), [](const Event& a, const Event& b) { return a.at_s < b.at_s; });

    rig_ = std::make_unique<sim::Rig>(config);
    next_event_ = 0;
    encoder_offset_m_ = 0.0;
    encoder_stale_ = false;
    driver_error_ = false;
    bus_back_at_.reset();
    stall_remaining_ = 0;
    pending_ = Duration::zero();
    active_ = false;
    make_outputs_safe();  // no commands before activation: the amplifier is unpowered
    declare_channels();
    if (timing_ == Timing::device && !scratch_) {
      device_ = std::make_unique<DeviceRig>(*rig_);
      if (std::string refused = DeviceClock::instance().attach(*device_, device); !refused.empty()) {
        device_.reset();
        s.fail_here(refused);
      }
    }
  }

  void detach_device() noexcept {
    if (!device_) return;
    DeviceClock::instance().detach(*device_);
    device_.reset();
  }

  void declare_channels() {
    channels_.clear();
    const auto add = [&](std::string name, ChannelKind kind, std::string unit) {
      channels_.push_back({std::move(name), kind, std::move(unit)});
      return channels_.size() - 1;
    };
    index_.encoder = add("encoder", ChannelKind::encoder_input, "m");
    index_.pressure_a = add("pressure_a", ChannelKind::analog_input, "Pa");
    index_.pressure_b = add("pressure_b", ChannelKind::analog_input, "Pa");
    if (valve_ == sim::ValveKind::proportional) {
      index_.spool_lvdt = add("spool_lvdt", ChannelKind::analog_input, "m");
      index_.valve_current = add("valve_current", ChannelKind::analog_input, "A");
      index_.command = add("current_ref", ChannelKind::analog_output, "A");
    } else {
      index_.command = add("opening_cmd", ChannelKind::analog_output, "1");
    }
    index_.enable = add("valve_enable", ChannelKind::digital_output, "1");
    index_.estop = add("estop", ChannelKind::digital_input, "1");
  }

  // Amplifier off, command at rest: a servo-valve centres, a proportional valve's spring returns
  // the spool to its rest stop.
  void make_outputs_safe() noexcept {
    if (device_) {
      device_->set_command(0.0);
      device_->set_enable(false);
      return;
    }
    if (!rig_) return;
    rig_->set_valve_command(0.0);
    rig_->set_valve_enable(false);
  }

  // `t` is the read's timestamp: a timed bus outage ends on the daemon's clock, which runs on while
  // the rig's stands still.
  void apply_due_events(Timestamp t) noexcept {
    // Half a step of slack: the rig's time is a sum of steps and carries rounding error.
    const double now = rig_->time_s() + 0.5 * rig_->config().step_s;
    for (; next_event_ < events_.size() && events_[next_event_].at_s <= now; ++next_event_) {
      const Event& e = events_[next_event_];
      sim::FaultInjection& faults = rig_->faults();
      if (e.estop) rig_->set_estop(*e.estop);
      if (e.load_kg) (void)rig_->set_load_mass(*e.load_kg);  // checked >= 0 at configure: taken
      if (e.valve_stuck) faults.valve_stuck = *e.valve_stuck;
      if (e.supply_lost) faults.supply_lost = *e.supply_lost;
      if (e.sensor) fault_of(faults, *e.sensor).mode = e.fault;
      if (e.encoder_jump_m) encoder_offset_m_ += *e.encoder_jump_m;
      if (e.encoder_stale) encoder_stale_ = *e.encoder_stale;
      if (e.driver_error) {
        driver_error_ = *e.driver_error;
        bus_back_at_.reset();
        if (e.driver_error_s) {
          bus_back_at_ = t + std::chrono::round<Duration>(std::chrono::duration<double>(*e.driver_error_s));
        }
      }
      if (e.stall_us) {
        stall_ns_ = *e.stall_us * 1000;
        stall_remaining_ = e.stall_cycles;
      }
    }
  }

  std::unique_ptr<sim::Rig> rig_;
  std::unique_ptr<DeviceRig> device_;  // timing = "device": the rig's mailbox, attached to the device thread
  bool scratch_ = false;               // a check_settings/plan driver: never attached
  sim::ValveKind valve_ = sim::ValveKind::servo;
  Timing timing_ = Timing::cycle;
  Duration step_{};
  Duration pending_{};  // simulated time owed to the rig in cycle timing, less than one step
  std::vector<ChannelInfo> channels_;
  Indices index_{};
  std::vector<Event> events_;
  std::size_t next_event_ = 0;
  bool active_ = false;
  // State of the I/O-path faults (events).
  double encoder_offset_m_ = 0.0;
  bool encoder_stale_ = false;
  bool driver_error_ = false;
  std::optional<Timestamp> bus_back_at_;  // a timed outage ends at this read timestamp
  toml::table settings_;  // the settings the rig was built from, to recognise a recovery
  bool rig_kept_ = false;  // on_error kept the rig for an on_configure with the same settings
  std::int64_t stall_ns_ = 0;
  std::int64_t stall_remaining_ = 0;  // read() calls still to stall
};

}  // namespace
}  // namespace hsa::io::sim_plugin

HSA_DRIVER_PLUGIN("sim", hsa::io::sim_plugin::SimDriver)
