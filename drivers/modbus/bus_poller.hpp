// The modbus plugin's bus thread: it owns the libmodbus context, polls the configured registers at
// its own rate and swaps the latest values with the RT thread through triple buffers, so the RT
// cycle never waits on the bus (docs/architecture.md, real-time rules).
//
// Each poll cycle: read every input block and hand the values to the RT thread, then write every
// output block (the RT thread's latest values while live, the safe values otherwise). While live,
// the writes wait, bounded by the cycle's end, for the RT thread's first publish computed from
// this cycle's inputs (write() reports which input cycle its values come from): so the command
// computed from a sample goes out in the cycle that read the sample. Written first and read
// after, as before, that command waited for the next cycle's writes: a whole poll period of
// sensor-to-actuator delay for nothing (bench/device-delay measures it at the device). The wait
// polls an atomic every 50 µs: the RT side only stores a number, no wake-up, no lock. A stalled
// RT side costs the wait the rest of the cycle, and the output timeout below still applies. Contiguous channels of one table share a single
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
//                       because a late answer would otherwise be taken for the next request's;
//                       timeouts are also counted on their own.
// Counters only grow; hsad's operator thread reads them (Driver::health) for status.
//
// The link's state (DriverHealth::Link) says what the device did last, not whether a socket is
// open: up once it answered (an exception is an answer), down when the connection failed or was
// refused or reset, not_answering after a timeout. A device that stopped answering often still
// accepts connections (a stopped process, a hung stack), so a reconnect leaves not_answering as
// it is until the device answers again; the state never flickers to up on a connect alone.
// The last error keeps the block it happened on, so an exception names its registers.
//
// A write the device refuses with an exception is more than a missed cycle: the device keeps its
// previous value (a valve left open) while the daemon believes its command went out. So while
// live, the first refused write is recorded as a write failure, with the exception code and the
// register block, and the driver turns it into IoStatus::write_error (a driver error in hsad,
// "write failed").
//
// Outputs are never left at a stale command: the safe values are written instead of the RT
// thread's
//   - while not live (before activation, after deactivation); deactivation waits, bounded, until
//     one full cycle of safe values has reached the device;
//   - once the RT side asked for them (request_safe, from Driver::make_safe), from the next block
//     written on, until the next activation, and for as long as the link is up;
//   - while the RT side has published nothing for output_timeout (a stalled daemon), counted in
//     output_timeouts once per cycle that wrote them. The clock starts at the first publish after
//     activation, so an activation the RT thread has not reached yet is no timeout.
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
#include "drivers/driver_health.hpp"
#include "drivers/modbus/modbus_settings.hpp"
#include "lockfree/triple_buffer.hpp"
#include "drivers/result.hpp"

struct _modbus;  // libmodbus's modbus_t, kept out of the driver's headers

namespace hsa::io::modbus {

// What the bus thread hands the RT thread; both vectors are indexed like the settings' channels
// (output entries unused) and sized once at construction.
struct InputSnapshot {
  std::vector<double> value;              // scaled, SI
  // io::monotonic_ns() of the sample; 0 = never read. The daemon's cycle time counts from an epoch
  // the driver does not know, so ages are taken on the raw clock both threads share, and the
  // RT side places the time on the daemon's timeline by the offset its reads measure
  // (timeline_offset.hpp).
  std::vector<std::int64_t> acquired_ns;
  std::uint64_t cycle = 0;  // the poll cycle that read it, from 1; 0 = none yet
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
  lockfree::TripleBuffer<InputSnapshot>& inputs() noexcept { return inputs_; }
  lockfree::TripleBuffer<std::vector<double>>& outputs() noexcept { return outputs_; }
  [[nodiscard]] DriverHealth::Link link() const noexcept { return link_.load(std::memory_order_relaxed); }
  [[nodiscard]] bool link_up() const noexcept { return link() == DriverHealth::Link::up; }
  [[nodiscard]] std::uint64_t timeouts() const noexcept { return timeouts_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t link_errors() const noexcept { return link_errors_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t transaction_errors() const noexcept {
    return transaction_errors_.load(std::memory_order_relaxed);
  }
  [[nodiscard]] std::uint64_t output_timeouts() const noexcept { return output_timeouts_.load(std::memory_order_relaxed); }

  // RT thread, after each outputs().publish(): the RT side is alive, and the values it published
  // were computed from the inputs of poll cycle `input_cycle` (InputSnapshot::cycle).
  void note_published(std::uint64_t input_cycle) noexcept {
    answered_cycle_.store(input_cycle, std::memory_order_release);
    published_.fetch_add(1, std::memory_order_release);
  }
  // RT thread (Driver::make_safe): safe values from the next block written until set_live(true).
  void request_safe() noexcept { safe_requested_.store(true, std::memory_order_release); }
  // RT thread: a live write was refused; write_failure() then says how (set once, never changed).
  [[nodiscard]] bool write_failed() const noexcept { return write_failed_.load(std::memory_order_acquire); }
  [[nodiscard]] const char* write_failure() const noexcept { return write_failure_; }

  // Lifecycle thread. Going live makes the bus thread write what the RT thread publishes; the
  // caller publishes a first buffer before (on_activate publishes the safe values, so nothing
  // from a previous activation leaks out).
  void set_live(bool live) {
    if (live) safe_requested_.store(false, std::memory_order_release);
    live_.store(live, std::memory_order_release);
  }
  // After set_live(false): waits until a whole cycle of safe values was written, or `timeout`.
  bool wait_safe_outputs_written(Duration timeout);
  // After set_live(true): waits until a whole cycle wrote the live values, a write was refused
  // (write_failed()) or `timeout` passed; true only for the first.
  bool wait_live_outputs_written(Duration timeout);
  // Waits until a cycle that began after the call has ended (whatever it wrote), or `timeout`:
  // after set_live(false), no cycle with live values is in flight any more.
  bool wait_cycle(Duration timeout);
  // Lifecycle thread, before set_live(true) and while the RT side does not call read or write:
  // forgets a refused write, so an activation judges the device afresh.
  void clear_write_failure() noexcept { write_failed_.store(false, std::memory_order_release); }
  // The last bus error, for messages ("Connection refused", "Connection timed out", and for an
  // exception its block: "Modbus exception 2 (Illegal data address) reading input registers
  // 200..200"), and whether there has been one.
  [[nodiscard]] std::string last_error() const;
  [[nodiscard]] bool had_error() const { return (last_error_.load(std::memory_order_relaxed) >> 32) != 0; }

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
  // One poll cycle, `deadline_ns` its end: false on a link error (the link must be reopened).
  bool cycle(std::stop_token& stop, std::int64_t deadline_ns);
  // Live: until the RT side published values computed from input cycle `n`, or the deadline.
  void wait_for_answer(std::stop_token& stop, std::uint64_t n, std::int64_t deadline_ns);
  bool write_block(const Block& b, const std::vector<double>& values);
  bool read_block(const Block& b);
  // Classifies errno after a failed transaction on `b` (nullptr: the connect); true when the
  // link survives it.
  bool count_error(const Block* b, bool writing);
  // A link error (`block` as in last_error_): the state it leaves the link in, timeouts counted.
  void note_link_error(int err, std::int32_t block);
  void record_write_failure(const Block& b, int err);
  // "Modbus exception 3 (Illegal data value) writing holding registers 0..1", or for another
  // error its text and the block ("Connection timed out reading input registers 0..5").
  [[nodiscard]] std::string describe_error(const Block& b, int err, bool writing) const;
  // Which values a block gets now: the RT thread's only while live, not asked to be safe and not
  // timed out; otherwise the safe values, except that a heartbeat keeps the last count the RT
  // side published. It stops counting, which is what a device watching it must see: a jump back
  // to its safe value would look like one more beat.
  const std::vector<double>& values_for_next_block(bool use_rt);
  void sleep_until(std::stop_token& stop, std::int64_t deadline_ns);

  ModbusSettings settings_;
  _modbus* ctx_ = nullptr;
  bool connected_ = false;  // bus thread only, after start()
  std::vector<Block> read_blocks_, write_blocks_;
  std::vector<std::uint16_t> registers_;
  std::vector<std::uint8_t> bits_;
  std::vector<double> safe_values_;
  std::vector<double> safe_now_;            // safe_values_ with the heartbeats' last counts
  std::vector<std::size_t> heartbeats_;     // indices of the heartbeat channels
  InputSnapshot work_;  // the bus thread's current view, copied into inputs_ each cycle

  lockfree::TripleBuffer<InputSnapshot> inputs_;
  lockfree::TripleBuffer<std::vector<double>> outputs_;
  std::atomic<DriverHealth::Link> link_{DriverHealth::Link::down};
  std::atomic<std::uint64_t> timeouts_{0};
  std::atomic<std::uint64_t> link_errors_{0};
  std::atomic<std::uint64_t> transaction_errors_{0};
  // The last error and its block in one word, so a reader never pairs one error with another's
  // block: errno in the high half; in the low half 0 for the connect, k + 1 for read_blocks_[k],
  // -(k + 1) for write_blocks_[k].
  std::atomic<std::uint64_t> last_error_{0};
  void store_error(int err, std::int32_t block) noexcept;
  std::atomic<bool> live_{false};
  std::atomic<bool> safe_requested_{false};
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> answered_cycle_{0};  // the input cycle of the last publish
  std::uint64_t input_cycle_ = 0;                 // bus thread: input cycles handed over
  std::atomic<std::uint64_t> output_timeouts_{0};
  std::atomic<bool> write_failed_{false};
  char write_failure_[200] = {};  // bus thread writes it once, before write_failed_ (release)
  // Bus thread only: the output timeout's clock.
  bool was_live_ = false;
  std::uint64_t seen_published_ = 0;      // published_ when it last changed
  std::uint64_t published_at_live_ = 0;   // published_ when the driver went live
  std::int64_t seen_published_ns_ = 0;    // when the bus thread saw it change
  // Bumped by wait_safe_outputs_written and wait_live_outputs_written; the last request a full
  // cycle of safe (not live) or of live values answered.
  std::atomic<std::uint64_t> written_request_{0};
  std::atomic<std::uint64_t> safe_written_{0};
  std::atomic<std::uint64_t> live_written_{0};
  std::atomic<std::uint64_t> cycled_{0};  // the last request a cycle ended after
  // Bumps the request, then waits until `written` answers it, `give_up()` or `timeout`.
  template <typename GiveUp>
  bool wait_written(const std::atomic<std::uint64_t>& written, Duration timeout, GiveUp give_up);
  // Only for sleeping: request_stop() wakes the wait, nothing else notifies. Members, because
  // libstdc++'s condition_variable_any allocates when constructed.
  std::mutex sleep_mutex_;
  std::condition_variable_any sleep_cv_;
  std::jthread thread_;
};

}  // namespace hsa::io::modbus
