#include "drivers/modbus/bus_poller.hpp"

#include <modbus/modbus.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "drivers/clock.hpp"

namespace hsa::io::modbus {
namespace {

bool is_register_table(Table t) { return t == Table::input_register || t == Table::holding_register; }

int max_block(Table table, bool write) {
  if (is_register_table(table)) return write ? MODBUS_MAX_WRITE_REGISTERS : MODBUS_MAX_READ_REGISTERS;
  return write ? MODBUS_MAX_WRITE_BITS : MODBUS_MAX_READ_BITS;
}

InputSnapshot empty_snapshot(std::size_t n) {
  return {std::vector<double>(n, 0.0), std::vector<std::int64_t>(n, 0)};
}

std::vector<double> safe_values_of(const ModbusSettings& s) {
  std::vector<double> v(s.channels.size(), 0.0);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = s.channels[i].safe_value;
  return v;
}

// A TCP connect to a loopback port in the ephemeral range with nobody listening can be given
// that very port as its source and "connect" to itself (simultaneous open). It would then read
// its own requests as answers, and hold the port so the server cannot come back on it.
bool connected_to_itself(int fd) {
  sockaddr_storage local{}, peer{};
  socklen_t local_len = sizeof local, peer_len = sizeof peer;
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_len) != 0 ||
      getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_len) != 0) {
    return false;
  }
  return local_len == peer_len && std::memcmp(&local, &peer, local_len) == 0;
}

// The device answered, or at least the bytes arrived: the link itself is fine.
bool is_transaction_error(int err) { return err >= EMBXILFUN && err <= EMBBADSLAVE; }

// The device answered with a Modbus exception: it understood the request and refused it.
bool is_exception(int err) { return err >= EMBXILFUN && err <= EMBXGTAR; }

const char* table_name(Table t) {
  switch (t) {
    case Table::coil: return "coils";
    case Table::discrete_input: return "discrete inputs";
    case Table::input_register: return "input registers";
    case Table::holding_register: return "holding registers";
  }
  return "?";
}

}  // namespace

BusPoller::BusPoller(ModbusSettings settings)
    : settings_(std::move(settings)),
      registers_(MODBUS_MAX_READ_REGISTERS, 0),
      bits_(MODBUS_MAX_READ_BITS, 0),
      safe_values_(safe_values_of(settings_)),
      safe_now_(safe_values_),
      work_(empty_snapshot(settings_.channels.size())),
      inputs_(work_),
      outputs_(safe_values_) {
  const LinkSettings& l = settings_.link;
  ctx_ = l.transport == Transport::tcp
             ? modbus_new_tcp_pi(l.host.c_str(), std::to_string(l.port).c_str())
             : modbus_new_rtu(l.device.c_str(), l.baud, l.parity, l.data_bits, l.stop_bits);
  if (ctx_ == nullptr) {
    throw std::runtime_error(l.describe() + ": libmodbus refused the link settings: " +
                             modbus_strerror(errno));
  }
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(l.response_timeout).count();
  const auto sec = static_cast<std::uint32_t>(us / 1'000'000);
  const auto usec = static_cast<std::uint32_t>(us % 1'000'000);
  if (modbus_set_slave(ctx_, l.unit_id) != 0 || modbus_set_response_timeout(ctx_, sec, usec) != 0 ||
      modbus_set_byte_timeout(ctx_, sec, usec) != 0) {
    const std::string reason = modbus_strerror(errno);
    modbus_free(ctx_);
    throw std::runtime_error(l.describe() + ": libmodbus refused unit_id " +
                             std::to_string(l.unit_id) + " or the timeouts: " + reason);
  }
  for (std::size_t i = 0; i < settings_.channels.size(); ++i) {
    if (settings_.channels[i].heartbeat) heartbeats_.push_back(i);
  }
  plan_blocks();
}

BusPoller::~BusPoller() {
  stop();
  close_link();
  modbus_free(ctx_);
}

void BusPoller::plan_blocks() {
  const auto& ch = settings_.channels;
  for (const Table table : {Table::coil, Table::discrete_input, Table::input_register, Table::holding_register}) {
    for (const bool write : {false, true}) {
      std::vector<std::size_t> members;
      for (std::size_t i = 0; i < ch.size(); ++i) {
        if (ch[i].table == table && is_input(ch[i].info.kind) != write) members.push_back(i);
      }
      std::sort(members.begin(), members.end(),
                [&](std::size_t a, std::size_t b) { return ch[a].address < ch[b].address; });
      std::vector<Block>& blocks = write ? write_blocks_ : read_blocks_;
      for (const std::size_t i : members) {
        Block* last = blocks.empty() || blocks.back().table != table ? nullptr : &blocks.back();
        // Only contiguous channels share a request: reading a gap could hit addresses the
        // device does not have, and writing one would clobber registers nobody configured.
        if (last != nullptr && last->address + last->count == ch[i].address &&
            last->count + ch[i].width() <= max_block(table, write)) {
          last->count += ch[i].width();
          last->channels.push_back(i);
        } else {
          blocks.push_back({table, ch[i].address, ch[i].width(), {i}});
        }
      }
    }
  }
}

Result BusPoller::connect() {
  if (open_link()) return Result::success();
  return Result::failure("cannot connect to " + settings_.link.describe() + ": " + last_error());
}

void BusPoller::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(std::move(stop)); });
}

void BusPoller::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

void BusPoller::store_error(int err, std::int32_t block) noexcept {
  const std::uint64_t word = (std::uint64_t{static_cast<std::uint32_t>(err)} << 32) | static_cast<std::uint32_t>(block);
  last_error_.store(word, std::memory_order_relaxed);
}

std::string BusPoller::describe_error(const Block& b, int err, bool writing) const {
  char text[200];
  if (is_exception(err)) {
    std::snprintf(text, sizeof text, "Modbus exception %d (%s) %s %s %d..%d", err - MODBUS_ENOBASE,
                  modbus_strerror(err), writing ? "writing" : "reading", table_name(b.table), b.address,
                  b.address + b.count - 1);
  } else {
    std::snprintf(text, sizeof text, "%s %s %s %d..%d", modbus_strerror(err), writing ? "writing" : "reading",
                  table_name(b.table), b.address, b.address + b.count - 1);
  }
  return text;
}

std::string BusPoller::last_error() const {
  const std::uint64_t word = last_error_.load(std::memory_order_relaxed);
  const int err = static_cast<int>(word >> 32);
  const auto block = static_cast<std::int32_t>(static_cast<std::uint32_t>(word));
  if (err == 0) return "no error";
  if (block > 0) return describe_error(read_blocks_[static_cast<std::size_t>(block - 1)], err, false);
  if (block < 0) return describe_error(write_blocks_[static_cast<std::size_t>(-block - 1)], err, true);
  return modbus_strerror(err);
}

template <typename GiveUp>
bool BusPoller::wait_written(const std::atomic<std::uint64_t>& written, Duration timeout, GiveUp give_up) {
  if (!thread_.joinable()) return false;
  const std::uint64_t request = written_request_.fetch_add(1, std::memory_order_acq_rel) + 1;
  const std::int64_t deadline = monotonic_ns() + timeout.count();
  // A plain bounded poll: this runs on the lifecycle thread, and a cycle takes milliseconds.
  while (written.load(std::memory_order_acquire) < request) {
    if (give_up() || monotonic_ns() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

bool BusPoller::wait_safe_outputs_written(Duration timeout) {
  return wait_written(safe_written_, timeout, [] { return false; });
}

bool BusPoller::wait_cycle(Duration timeout) {
  return wait_written(cycled_, timeout, [] { return false; });
}

bool BusPoller::wait_live_outputs_written(Duration timeout) {
  return wait_written(live_written_, timeout, [this] { return write_failed(); });
}

bool BusPoller::open_link() {
  if (modbus_connect(ctx_) != 0) {
    // libmodbus gives up a TCP connect still in progress after its timeout with EINPROGRESS: the
    // peer did not complete the handshake in time (a stopped device's full backlog), a timeout.
    const int err = errno == EINPROGRESS ? ETIMEDOUT : errno;
    modbus_close(ctx_);  // a failed connect may leave a socket behind
    note_link_error(err, 0);
    return false;
  }
  if (settings_.link.transport == Transport::tcp && connected_to_itself(modbus_get_socket(ctx_))) {
    modbus_close(ctx_);
    note_link_error(ECONNREFUSED, 0);
    return false;
  }
  connected_ = true;
  // A device that stopped answering may still accept a connection: it is up once it answers.
  if (link() != DriverHealth::Link::not_answering) link_.store(DriverHealth::Link::up, std::memory_order_relaxed);
  return true;
}

void BusPoller::close_link() {
  if (connected_) modbus_close(ctx_);
  connected_ = false;
  if (link() == DriverHealth::Link::up) link_.store(DriverHealth::Link::down, std::memory_order_relaxed);
}

void BusPoller::sleep_until(std::stop_token& stop, std::int64_t deadline_ns) {
  const std::int64_t left = deadline_ns - monotonic_ns();
  // Already due (a cycle that took its whole period): no wait at all. A timed wait on an expired
  // deadline still goes through the futex and its timer, which cost about 75 µs a cycle here
  // (bench_modbus), a third of the rate the bus could otherwise reach.
  if (left <= 0) return;
  std::unique_lock lock(sleep_mutex_);
  sleep_cv_.wait_for(lock, stop, std::chrono::nanoseconds(left), [] { return false; });
}

void BusPoller::run(std::stop_token stop) {
  const LinkSettings& l = settings_.link;
  Duration backoff = l.reconnect_min;
  while (!stop.stop_requested()) {
    if (!connected_) {
      if (!open_link()) {
        link_errors_.fetch_add(1, std::memory_order_relaxed);
        sleep_until(stop, monotonic_ns() + backoff.count());
        backoff = std::min(backoff * 2, l.reconnect_max);
        continue;
      }
      backoff = l.reconnect_min;
    }
    const std::int64_t next = monotonic_ns() + l.poll_period.count();
    if (!cycle(stop, next)) {
      close_link();  // reopened at once on the next turn; backoff only after a failed connect
      continue;
    }
    sleep_until(stop, next);
  }
}

const std::vector<double>& BusPoller::values_for_next_block(bool use_rt) {
  // Checked before every block: a make_safe that arrives mid-cycle is obeyed from the next write.
  if (use_rt && !safe_requested_.load(std::memory_order_acquire)) return outputs_.front();
  for (const std::size_t i : heartbeats_) safe_now_[i] = outputs_.front()[i];
  return safe_now_;
}

void BusPoller::record_write_failure(const Block& b, int err) {
  if (write_failed_.load(std::memory_order_relaxed)) return;  // the first failure is the cause
  std::snprintf(write_failure_, sizeof write_failure_, "%s of %s", describe_error(b, err, true).c_str(),
                settings_.link.describe().c_str());
  write_failed_.store(true, std::memory_order_release);
}

void BusPoller::wait_for_answer(std::stop_token& stop, std::uint64_t n, std::int64_t deadline_ns) {
  // At most about 40 looks per poll period, and every 50 µs at the shipped 2 ms: a longer poll
  // period (a slow bus, an emulated CPU) must not become a thread that wakes every 50 µs.
  const std::int64_t step_ns = std::max<std::int64_t>(50'000, settings_.link.poll_period.count() / 40);
  const timespec poll{0, static_cast<long>(std::min<std::int64_t>(step_ns, 999'999'999))};
  while (answered_cycle_.load(std::memory_order_acquire) < n && !stop.stop_requested() &&
         !safe_requested_.load(std::memory_order_acquire) && monotonic_ns() < deadline_ns) {
    nanosleep(&poll, nullptr);
  }
}

bool BusPoller::cycle(std::stop_token& stop, std::int64_t deadline_ns) {
  // Read the request before the mode: a deactivation clears live_ and then bumps the request, an
  // activation sets it and then bumps it, so a cycle that sees the new request sees the new mode.
  const std::uint64_t request = written_request_.load(std::memory_order_acquire);
  const bool live = live_.load(std::memory_order_acquire);
  bool link_ok = true;
  for (const Block& b : read_blocks_) {
    if (read_block(b)) {
      link_.store(DriverHealth::Link::up, std::memory_order_relaxed);
    } else if (!count_error(&b, false)) {
      link_ok = false;
      break;
    }
  }
  InputSnapshot& out = inputs_.back();
  std::copy(work_.value.begin(), work_.value.end(), out.value.begin());
  std::copy(work_.acquired_ns.begin(), work_.acquired_ns.end(), out.acquired_ns.begin());
  out.cycle = ++input_cycle_;
  inputs_.publish();
  if (!link_ok) {
    cycled_.store(request, std::memory_order_release);
    return false;
  }
  if (live) wait_for_answer(stop, input_cycle_, deadline_ns);

  outputs_.fetch();
  const std::uint64_t published = published_.load(std::memory_order_acquire);
  const std::int64_t now = monotonic_ns();
  if (live && !was_live_) published_at_live_ = published;
  was_live_ = live;
  if (published != seen_published_) {
    seen_published_ = published;
    seen_published_ns_ = now;
  }
  const bool armed = live && published != published_at_live_;  // the RT side wrote since activation
  const bool timed_out =
      armed && !safe_requested_.load(std::memory_order_acquire) &&
      now - seen_published_ns_ > settings_.link.output_timeout.count();
  if (timed_out) output_timeouts_.fetch_add(1, std::memory_order_relaxed);
  const bool use_rt = live && !timed_out;
  bool all_written = true;
  for (const Block& b : write_blocks_) {
    if (write_block(b, values_for_next_block(use_rt))) {
      link_.store(DriverHealth::Link::up, std::memory_order_relaxed);
    } else {
      all_written = false;
      const int err = errno;
      if (live && is_exception(err)) record_write_failure(b, err);
      errno = err;
      if (!count_error(&b, true)) {
        link_ok = false;
        break;
      }
    }
  }
  if (all_written) (live ? live_written_ : safe_written_).store(request, std::memory_order_release);
  cycled_.store(request, std::memory_order_release);
  return link_ok;
}

bool BusPoller::count_error(const Block* b, bool writing) {
  const int err = errno;
  std::int32_t block = 0;
  if (b != nullptr) {
    const std::vector<Block>& blocks = writing ? write_blocks_ : read_blocks_;
    const auto k = static_cast<std::int32_t>(b - blocks.data()) + 1;
    block = writing ? -k : k;
  }
  if (is_transaction_error(err)) {
    store_error(err, block);
    link_.store(DriverHealth::Link::up, std::memory_order_relaxed);  // it answered
    transaction_errors_.fetch_add(1, std::memory_order_relaxed);
    // After a garbled frame the rest of it may still be in flight: drop it so it is not taken
    // for the next answer.
    if (err == EMBBADCRC || err == EMBBADDATA || err == EMBBADSLAVE) modbus_flush(ctx_);
    return true;
  }
  link_errors_.fetch_add(1, std::memory_order_relaxed);
  note_link_error(err, block);
  return false;
}

void BusPoller::note_link_error(int err, std::int32_t block) {
  store_error(err, block);
  if (err == ETIMEDOUT) {
    timeouts_.fetch_add(1, std::memory_order_relaxed);
    link_.store(DriverHealth::Link::not_answering, std::memory_order_relaxed);
  } else {
    link_.store(DriverHealth::Link::down, std::memory_order_relaxed);
  }
}

bool BusPoller::write_block(const Block& b, const std::vector<double>& values) {
  const auto& ch = settings_.channels;
  if (b.table == Table::coil) {
    for (std::size_t k = 0; k < b.channels.size(); ++k) {
      const std::size_t i = b.channels[k];
      const double v = std::isnan(values[i]) ? ch[i].safe_value : values[i];
      bits_[k] = v != 0.0 ? 1 : 0;
    }
    return b.count == 1 ? modbus_write_bit(ctx_, b.address, bits_[0]) == 1
                        : modbus_write_bits(ctx_, b.address, b.count, bits_.data()) == b.count;
  }
  int offset = 0;
  for (const std::size_t i : b.channels) {
    const ChannelMap& c = ch[i];
    // NaN would encode as garbage: a command nobody can compute is replaced by the safe one.
    const double v = std::isnan(values[i]) ? c.safe_value : values[i];
    encode(c.type, c.order, (v - c.offset) / c.scale,
           std::span(registers_).subspan(static_cast<std::size_t>(offset), static_cast<std::size_t>(c.width())));
    offset += c.width();
  }
  // A single register goes with function 06, which every device implements; more with 16.
  return b.count == 1 ? modbus_write_register(ctx_, b.address, registers_[0]) == 1
                      : modbus_write_registers(ctx_, b.address, b.count, registers_.data()) == b.count;
}

bool BusPoller::read_block(const Block& b) {
  const std::int64_t sent = monotonic_ns();
  int rc = -1;
  switch (b.table) {
    case Table::coil: rc = modbus_read_bits(ctx_, b.address, b.count, bits_.data()); break;
    case Table::discrete_input: rc = modbus_read_input_bits(ctx_, b.address, b.count, bits_.data()); break;
    case Table::input_register: rc = modbus_read_input_registers(ctx_, b.address, b.count, registers_.data()); break;
    case Table::holding_register: rc = modbus_read_registers(ctx_, b.address, b.count, registers_.data()); break;
  }
  if (rc != b.count) {
    if (rc >= 0) errno = EMBBADDATA;  // a short answer is a malformed one
    return false;
  }
  // The device sampled somewhere between request and answer: the midpoint is the best guess.
  const std::int64_t acquired = sent + (monotonic_ns() - sent) / 2;
  const auto& ch = settings_.channels;
  int offset = 0;
  for (const std::size_t i : b.channels) {
    const ChannelMap& c = ch[i];
    if (is_register_table(b.table)) {
      const double raw = decode(c.type, c.order,
                                std::span<const std::uint16_t>(registers_).subspan(
                                    static_cast<std::size_t>(offset), static_cast<std::size_t>(c.width())));
      work_.value[i] = raw * c.scale + c.offset;
    } else {
      work_.value[i] = bits_[static_cast<std::size_t>(offset)] != 0 ? 1.0 : 0.0;
    }
    work_.acquired_ns[i] = acquired;
    offset += c.width();
  }
  return true;
}

}  // namespace hsa::io::modbus
