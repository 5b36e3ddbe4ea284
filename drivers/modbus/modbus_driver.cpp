// The "modbus" driver plugin: channels mapped onto the registers and bits of one Modbus device,
// over TCP or RTU (libmodbus). Settings: see drivers/modbus/modbus_settings.hpp.
//
// Threads. All bus traffic runs on the plugin's own thread (BusPoller) at poll_period_s; read()
// and write() on the RT thread only swap buffers with it (TripleBuffer: wait-free, no lock, no
// allocation) and never wait on the bus. So the RT cycle may run much faster than the bus, and a
// dead device costs it nothing but stale samples.
//
// Samples. Every input carries the time the device was polled (the midpoint of request and
// answer on CLOCK_MONOTONIC), placed on the daemon's timeline once (timeline_offset.hpp: a read()
// the host delayed does not squeeze the interval between two samples), and the same timestamp for
// as long as no newer sample arrives. Its age is measured on CLOCK_MONOTONIC at each read(). Status: disconnected until the first successful poll, stale once
// older than its max_age_s, ok otherwise. read() itself returns ok whatever the link does: the
// sample status is how a dead bus reaches the supervisor, which decides when stale means fault.
// A write the device refused with an exception is different (bus_poller.hpp): from then on read()
// and write() return IoStatus::write_error (a write failed, though read() is where the RT side
// learns it first), and failure_reason() gives the exception code and block.
//
// make_safe (RT thread) asks the bus thread for the safe values from its next block written on,
// until the next activation; it keeps writing them while the driver is in error, as long as the
// link is up. If the RT side stops calling write() for output_timeout_s, the bus thread writes
// the safe values too (counted in output_timeouts). A heartbeat channel (modbus_settings.hpp)
// carries write()'s call counter, so the device itself can tell a live RT side from a stalled one.
//
// Status channels, declared after the configured ones (status always ok):
//   link_up             digital input   1 while the link is open and the device answers (a device
//                                       that stopped answering reads 0: health says not answering)
//   link_errors         analog input    count of connect failures, timeouts, resets
//   transaction_errors  analog input    count of exception answers and malformed frames
//   output_timeouts     analog input    bus cycles that wrote the safe values because write()
//                                       had not run for output_timeout_s
//
// Lifecycle. on_configure parses the settings and opens the link once, synchronously, so a wrong
// address or a dead device is reported at configure with its reason; then the bus thread starts,
// writing the safe values of the outputs every cycle. on_activate lets the RT values through,
// after one live cycle has written the outputs (bounded): a device that refuses them fails the
// activation with its exception and block, and the driver stays inactive;
// on_deactivate returns to the safe values and waits (bounded) until the device has them.
// on_cleanup stops the thread and closes the link.
//
// The three counters are cumulative over the driver's life: a recovery (on_cleanup, then
// on_configure with a new bus thread) carries them over, so that the errors that led to it stay
// visible in status after the link is back.
#include <algorithm>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <filesystem>
#include <vector>

#include "drivers/clock.hpp"
#include "drivers/driver.hpp"
#include "drivers/modbus/bus_poller.hpp"
#include "drivers/modbus/modbus_settings.hpp"
#include "drivers/plugin_abi.hpp"
#include "drivers/table_reader.hpp"
#include "drivers/timeline_offset.hpp"

namespace hsa::io::modbus {
namespace {

// The mapped channels, then the link's own status channels.
std::vector<ChannelInfo> declared_channels(const std::vector<ChannelMap>& maps) {
  std::vector<ChannelInfo> channels;
  for (const ChannelMap& c : maps) channels.push_back(c.info);
  channels.push_back({link_up_channel, ChannelKind::digital_input, "1"});
  channels.push_back({link_errors_channel, ChannelKind::analog_input, "1"});
  channels.push_back({transaction_errors_channel, ChannelKind::analog_input, "1"});
  channels.push_back({output_timeouts_channel, ChannelKind::analog_input, "1"});
  return channels;
}

// A device path with its links resolved (/dev/serial/by-id/... and /dev/ttyUSB0 are one line); as
// given when it does not exist yet.
std::string resolved_path(const std::string& path) {
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::canonical(path, error);
  return error ? std::filesystem::path(path).lexically_normal().string() : resolved.string();
}

class ModbusDriver final : public Driver {
 public:
  ~ModbusDriver() override { poller_.reset(); }

  // The settings alone: no link is opened and no thread started.
  Result check_settings(const toml::table& table) const override {
    return Result::of([&] { (void)parse_modbus_settings(table); });
  }

  // The link with the settings' defaults applied (TCP port 502), so that an omitted port and 502
  // are one device; a serial line by its resolved path.
  Result plan(const toml::table& table, DriverPlan& plan) const override {
    return Result::of([&] {
      const ModbusSettings settings = parse_modbus_settings(table);
      const LinkSettings& link = settings.link;
      plan.devices = {link.transport == Transport::tcp ? "modbus-tcp:" + link.host + ":" + std::to_string(link.port)
                                                       : "serial:" + resolved_path(link.device)};
      plan.channels = declared_channels(settings.channels);
    });
  }

  Result on_configure(const toml::table& table) override {
    try {
      configure(table);
    } catch (const std::exception& e) {  // ConfigError, or libmodbus refusing the link
      release();
      return Result::failure(e.what());
    }
    if (Result r = poller_->connect(); !r) {
      release();
      return r;
    }
    poller_->start();
    return Result::success();
  }

  std::span<const ChannelInfo> channels() const override { return channels_; }

  Result on_activate() override {
    // The RT side has not written yet: start from the safe values, not from whatever the last
    // activation left in the buffer. Lifecycle steps never overlap write(), so this thread may
    // act as the buffer's writer here.
    poller_->clear_write_failure();
    std::vector<double>& out = poller_->outputs().back();
    for (std::size_t i = 0; i < maps_.size(); ++i) out[i] = maps_[i].safe_value;
    poller_->outputs().publish();
    poller_->set_live(true);
    // A device that refuses the outputs is refused here, with its reason, rather than handed to
    // the RT side to fail a cycle later: a recovery (hsactl reset) against a device that still
    // refuses then fails naming the cause, and never lets a reset through in between. A device
    // that does not answer in time is no refusal: its inputs go stale and say so.
    if (!poller_->wait_live_outputs_written(one_cycle_of_writes()) && poller_->write_failed()) {
      const std::string why = "write failed: " + std::string(poller_->write_failure());
      // Inactive again, as before: once a cycle has started without live values (none in flight
      // can record a refusal after it), the refusal is forgotten, so read() carries on.
      poller_->set_live(false);
      (void)poller_->wait_cycle(one_cycle_of_writes());
      poller_->clear_write_failure();
      return Result::failure(why);
    }
    return Result::success();
  }

  Result on_deactivate() override {
    poller_->set_live(false);
    const auto& l = poller_->settings().link;
    if (!poller_->wait_safe_outputs_written(one_cycle_of_writes())) {
      return Result::failure("outputs not confirmed at their safe values on " + l.describe() +
                             " (the bus thread keeps trying): " + poller_->last_error());
    }
    return Result::success();
  }

  Result on_cleanup() override {
    release();
    return Result::success();
  }

  Result on_error() override { return on_cleanup(); }

  IoStatus read(Timestamp t, Duration, std::span<ChannelSlot> slots) noexcept override {
    lockfree::TripleBuffer<InputSnapshot>& inputs = poller_->inputs();
    inputs.fetch();
    const InputSnapshot& in = inputs.front();
    input_cycle_ = in.cycle;
    const std::int64_t now = monotonic_ns();
    timeline_.measure(t, now);
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (!is_input(maps_[i].info.kind)) continue;
      const std::int64_t acquired = in.acquired_ns[i];
      if (acquired == 0) {
        slots[i] = {slots[i].value, t, SampleStatus::disconnected};
        continue;
      }
      const Duration age{std::max<std::int64_t>(0, now - acquired)};
      if (acquired != acquired_[i]) {  // a new sample: place it on the daemon's timeline once
        acquired_[i] = acquired;
        stamp_[i] = timeline_.on_timeline(acquired);
      }
      slots[i] = {in.value[i], stamp_[i], age > maps_[i].max_age ? SampleStatus::stale : SampleStatus::ok};
    }
    const std::size_t n = maps_.size();
    slots[n] = {poller_->link_up() ? 1.0 : 0.0, t, SampleStatus::ok};
    const Counts counts = counts_now();
    slots[n + 1] = {static_cast<double>(counts.link_errors), t, SampleStatus::ok};
    slots[n + 2] = {static_cast<double>(counts.transaction_errors), t, SampleStatus::ok};
    slots[n + 3] = {static_cast<double>(counts.output_timeouts), t, SampleStatus::ok};
    return poller_->write_failed() ? IoStatus::write_error : IoStatus::ok;
  }

  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot> slots) noexcept override {
    if (poller_->write_failed()) return IoStatus::write_error;
    lockfree::TripleBuffer<std::vector<double>>& outputs = poller_->outputs();
    std::vector<double>& out = outputs.back();
    // 0..32767 and around: exact in every register type (int16 included).
    const double beat = static_cast<double>(heartbeat_++ % 32768);
    for (std::size_t i = 0; i < maps_.size(); ++i) {
      if (is_input(maps_[i].info.kind)) continue;
      out[i] = maps_[i].heartbeat ? beat : slots[i].value;
    }
    outputs.publish();
    poller_->note_published(input_cycle_);
    return IoStatus::ok;
  }

  void make_safe() noexcept override {
    if (poller_) poller_->request_safe();
  }

  std::string_view failure_reason() const noexcept override {
    return poller_ && poller_->write_failed() ? std::string_view(poller_->write_failure()) : std::string_view{};
  }

  // The bus thread's atomics: asking never waits for the bus.
  DriverHealth health() const override {
    if (!poller_) return {};
    DriverHealth h;
    h.link = poller_->link();
    if (poller_->had_error()) h.last_error = poller_->settings().link.describe() + ": " + poller_->last_error();
    const Counts counts = counts_now();
    h.counters = {{link_errors_channel, counts.link_errors},
                  {"timeouts", counts.timeouts},
                  {transaction_errors_channel, counts.transaction_errors},
                  {output_timeouts_channel, counts.output_timeouts}};
    return h;
  }

 private:
  struct Counts {
    std::uint64_t link_errors = 0;
    std::uint64_t timeouts = 0;  // of the link errors, those the device did not answer in time
    std::uint64_t transaction_errors = 0;
    std::uint64_t output_timeouts = 0;
  };

  // Long enough for a cycle in progress plus a full cycle of writes, each bounded.
  [[nodiscard]] Duration one_cycle_of_writes() const {
    const auto& l = poller_->settings().link;
    return 2 * l.poll_period + 4 * l.response_timeout * (1 + outputs_count_) + std::chrono::milliseconds(100);
  }

  // Those of the bus threads before this one, and this one's.
  [[nodiscard]] Counts counts_now() const noexcept {
    Counts c = carried_;
    if (poller_) {
      c.link_errors += poller_->link_errors();
      c.timeouts += poller_->timeouts();
      c.transaction_errors += poller_->transaction_errors();
      c.output_timeouts += poller_->output_timeouts();
    }
    return c;
  }

  void configure(const toml::table& table) {
    ModbusSettings settings = parse_modbus_settings(table);
    maps_ = settings.channels;
    outputs_count_ = static_cast<int>(std::count_if(
        maps_.begin(), maps_.end(), [](const ChannelMap& c) { return !is_input(c.info.kind); }));
    channels_ = declared_channels(maps_);
    acquired_.assign(maps_.size(), 0);
    stamp_.assign(maps_.size(), Timestamp{});
    poller_ = std::make_unique<BusPoller>(std::move(settings));
  }

  void release() {
    carried_ = counts_now();
    poller_.reset();  // stops the thread, closes the link
    maps_.clear();
    channels_.clear();
  }

  std::unique_ptr<BusPoller> poller_;
  Counts carried_;  // the counts of the bus threads that came before poller_
  std::vector<ChannelMap> maps_;  // the configured channels, indexed like their slots
  std::vector<ChannelInfo> channels_;
  int outputs_count_ = 0;
  // RT thread: the acquisition time of the sample each slot holds and its timestamp. The
  // timestamp is computed once per sample and then kept, so it changes exactly when the sample
  // does: the supervisor tells a fresh sample from a repeated one by its timestamp.
  std::vector<std::int64_t> acquired_;
  std::vector<Timestamp> stamp_;
  TimelineOffset timeline_;  // RT thread
  std::uint64_t heartbeat_ = 0;  // RT thread: write() calls, for heartbeat channels
  std::uint64_t input_cycle_ = 0;  // RT thread: the poll cycle of the inputs read() last had
};

}  // namespace
}  // namespace hsa::io::modbus

HSA_DRIVER_PLUGIN("modbus", hsa::io::modbus::ModbusDriver)
