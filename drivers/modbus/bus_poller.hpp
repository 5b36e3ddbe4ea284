// The modbus plugin's bus thread: it owns the libmodbus context, polls the configured registers at
// its own rate and swaps the latest values with the RT thread through triple buffers, so the RT
// cycle never waits on the bus (DESIGN.md, real-time rules).
//
// Each poll cycle: write every output block (the RT thread's latest values while live, the safe
// values otherwise), then read every input block. Contiguous channels of one table share a single
// request (up to libmodbus's per-request maximum). Every transaction is bounded by the response
// timeout (and the same inter-byte timeout), so one cycle takes at most a known time.
//
// Errors come in two kinds, counted separately:
//   transaction errors: the device answered, but with an exception (illegal address, busy, ...)
//                       or a malformed/CRC-failed frame. The link stays up; only that block's
//                       channels miss this cycle and age.
//   link errors:        connect failures, timeouts, resets. The link is closed and reopened,
//                       at once the first time and then with a doubling backoff between
//                       reconnect_min and reconnect_max. A timeout counts as a link error
//                       because a late answer would otherwise be taken for the next request's.
// Counters only grow; the RT side publishes them in status channels.
//
// Outputs are never left at a stale command: while not live (before activation, after
// deactivation) each cycle writes the safe values, and deactivation waits, bounded, until one
// full cycle of safe values has reached the device.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "drivers/clock.hpp"
#include "drivers/modbus/modbus_settings.hpp"
#include "drivers/modbus/triple_buffer.hpp"
#include "drivers/result.hpp"

struct _modbus;  // libmodbus's modbus_t, kept out of the driver's headers

namespace hsa::io::modbus {

// What the bus thread hands the RT thread; both vectors are indexed like the settings' channels
// (output entries unused) and sized once at construction.
struct InputSnapshot {
  std::vector<double> value;              // scaled, SI
  // io::monotonic_ns() of the sample; 0 = never read. The daemon's cycle time counts from an epoch
  // the driver does not know, so ages are taken on the raw clock both threads share and only then
  // placed on the daemon's timeline (timestamp = t - age).
  std::vector<std::int64_t> acquired_ns;
};

class BusPoller {
 public:
  // Creates the libmodbus context; throws std::runtime_error when libmodbus rejects the link
  // parameters. Nothing is opened yet.
  explicit BusPoller(ModbusSettings settings);
  ~BusPoller();  // stops the thread and closes the link
  BusPoller(const BusPoller&) = delete;
  BusPoller& operator=(const BusPoller&) = delete;

  // Opens the link once, synchronously (bounded by the response timeout): the failure says which
  // link and why, for on_configure.
  Result connect();
  // Starts the bus thread; it polls the link connect() opened and reconnects when it drops.
  void start();
  void stop();

  // RT thread: reader of inputs(), writer of outputs(). Neither blocks.
  TripleBuffer<InputSnapshot>& inputs() { return inputs_; }
  TripleBuffer<std::vector<double>>& outputs() { return outputs_; }
  [[nodiscard]] bool link_up() const { return link_up_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t link_errors() const { return link_errors_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t transaction_errors() const {
    return transaction_errors_.load(std::memory_order_relaxed);
  }

  // Lifecycle thread. Going live makes the bus thread write what the RT thread publishes; the
  // caller publishes a first buffer before (on_activate publishes the safe values, so nothing
  // from a previous activation leaks out).
  void set_live(bool live) { live_.store(live, std::memory_order_release); }
  // After set_live(false): waits until a whole cycle of safe values was written, or `timeout`.
  bool wait_safe_outputs_written(Duration timeout);
  // The last bus error, for messages ("Connection refused", "Illegal data address", ...).
  [[nodiscard]] std::string last_error() const;

  [[nodiscard]] const ModbusSettings& settings() const { return settings_; }

 private:
  struct Block {
    Table table;
    int address;
    int count;                          // registers or bits
    std::vector<std::size_t> channels;  // indices into settings_.channels, by address
  };

  void plan_blocks();
  void run(std::stop_token stop);
  bool open_link();
  void close_link();
  bool cycle();               // false on a link error: the link must be reopened
  bool write_block(const Block& b, const std::vector<double>& values);
  bool read_block(const Block& b);
  bool count_error();         // classifies errno; true when the link survives it
  void sleep_until(std::stop_token& stop, std::int64_t deadline_ns);

  ModbusSettings settings_;
  _modbus* ctx_ = nullptr;
  bool connected_ = false;  // bus thread only, after start()
  std::vector<Block> read_blocks_, write_blocks_;
  std::vector<std::uint16_t> registers_;
  std::vector<std::uint8_t> bits_;
  std::vector<double> safe_values_;
  InputSnapshot work_;  // the bus thread's current view, copied into inputs_ each cycle

  TripleBuffer<InputSnapshot> inputs_;
  TripleBuffer<std::vector<double>> outputs_;
  std::atomic<bool> link_up_{false};
  std::atomic<std::uint64_t> link_errors_{0};
  std::atomic<std::uint64_t> transaction_errors_{0};
  std::atomic<int> last_errno_{0};
  std::atomic<bool> live_{false};
  std::atomic<std::uint64_t> safe_request_{0};  // bumped by wait_safe_outputs_written
  std::atomic<std::uint64_t> safe_written_{0};  // the last request a full safe cycle answered
  // Only for sleeping: request_stop() wakes the wait, nothing else notifies. Members, because
  // libstdc++'s condition_variable_any allocates when constructed.
  std::mutex sleep_mutex_;
  std::condition_variable_any sleep_cv_;
  std::jthread thread_;
};

}  // namespace hsa::io::modbus
