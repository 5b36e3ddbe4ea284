#include "tools/hsa_simdev/can_server.hpp"

#include <linux/can.h>
#include <sys/socket.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include <toml++/toml.h>

#include "drivers/table_reader.hpp"
#include "drivers/socketcan/can_settings.hpp"
#include "drivers/socketcan/can_socket.hpp"
#include "drivers/socketcan/frame_exchange.hpp"
#include "tools/hsa_simdev/period_timer.hpp"

namespace hsa::simdev {
namespace {

using io::socketcan::CanSettings;

// The rig's side of the map in can_server.hpp: what the controller sends is its input.
// max_age_s is irrelevant here: the communication watchdog (rig_runner.hpp) guards the command.
CanSettings rig_side_settings(const std::string& interface) {
  const std::string text = "interface = \"" + interface + "\"\n" + R"(
[[frames]]
id = 0x201
direction = "input"
length = 3
[[frames.channels]]
name = "valve_command"
kind = "analog_input"
byte_offset = 0
bytes = 2
signed = true
scale = 1e-4
[[frames.channels]]
name = "valve_enable"
kind = "digital_input"
byte_offset = 2
[[frames]]
id = 0x181
direction = "output"
length = 4
[[frames.channels]]
name = "position"
kind = "analog_output"
byte_offset = 0
bytes = 4
signed = true
scale = 1e-6
unit = "m"
[[frames]]
id = 0x281
direction = "output"
length = 2
[[frames.channels]]
name = "watchdog_tripped"
kind = "digital_output"
byte_offset = 0
[[frames.channels]]
name = "watchdog_trips"
kind = "analog_output"
byte_offset = 1
bytes = 1
)";
  return io::socketcan::parse_can_settings(toml::parse(text));
}

// Slots, in the order the settings declare the channels.
enum Slot : std::size_t {
  valve_command_slot,
  valve_enable_slot,
  position_slot,
  watchdog_tripped_slot,
  watchdog_trips_slot,
  length_errors_slot
};
// Output frames, in the order the settings declare them.
enum OutputFrame : std::size_t { position_frame, status_frame };

}  // namespace

CanServer::CanServer(RigRunner& rig, const std::string& interface, double period_s)
    : rig_(rig), period_s_(period_s) {
  try {
    exchange_ = std::make_unique<io::socketcan::FrameExchange>(rig_side_settings(interface));
    socket_ = std::make_unique<io::socketcan::CanSocket>(exchange_->settings());
  } catch (const std::exception& e) {
    throw std::runtime_error("CAN: " + std::string(e.what()));
  }
}

CanServer::~CanServer() { stop(); }

void CanServer::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(std::move(stop)); });
}

void CanServer::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

void CanServer::run(std::stop_token stop) {
  std::vector<io::ChannelSlot> slots(exchange_->channels().size());
  io::Timestamp last_command{-1};
  PeriodTimer timer(period_s_);
  while (!stop.stop_requested()) {
    const io::Timestamp t{io::monotonic_ns()};
    for (int n = 0; n < 64; ++n) {
      canfd_frame frame;
      const ssize_t got = recv(socket_->fd(), &frame, sizeof frame, MSG_DONTWAIT);
      if (got < 0) break;
      if (got == static_cast<ssize_t>(CAN_MTU)) exchange_->accept(frame, false, t);
    }
    exchange_->fill_inputs(t, slots);
    length_errors_.store(static_cast<std::uint64_t>(slots[length_errors_slot].value), std::memory_order_relaxed);
    const io::ChannelSlot& command = slots[valve_command_slot];
    if (command.status == io::SampleStatus::ok && command.timestamp != last_command) {
      last_command = command.timestamp;
      applied_.fetch_add(1, std::memory_order_relaxed);
      rig_.set_can_valve(command.value, slots[valve_enable_slot].value != 0.0);
      // Taken at the drain: the delay probe's time for it is up to one period after its arrival.
      rig_.note_valve_command(command.value, t.count());
    }
    rig_.check_can_watchdog();

    const auto send_due = [&](OutputFrame k) {
      if (const canfd_frame* frame = exchange_->due_output(k, t, slots)) {
        if (send(socket_->fd(), frame, CAN_MTU, MSG_DONTWAIT) == static_cast<ssize_t>(CAN_MTU)) {
          exchange_->mark_sent(k, t);
          if (k == position_frame) sent_.fetch_add(1, std::memory_order_relaxed);
        }
      }
    };
    const sim::SensorReading encoder = rig_.outputs().readings.encoder_m;
    if (encoder.connected && std::isfinite(encoder.value)) {
      slots[position_slot].value = encoder.value;
      send_due(position_frame);
    }
    const WatchdogState watchdog = rig_.watchdog();
    slots[watchdog_tripped_slot].value = watchdog.tripped ? 1.0 : 0.0;
    slots[watchdog_trips_slot].value = static_cast<double>(watchdog.trips % 256);
    send_due(status_frame);

    timer.wait_next();
  }
}

}  // namespace hsa::simdev
