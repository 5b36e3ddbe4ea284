#include "tools/hsa_simdev/modbus_server.hpp"

#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "drivers/clock.hpp"
#include "tools/hsa_simdev/register_map.hpp"

namespace hsa::simdev {
namespace {

void put_u32(std::uint16_t* regs, int address, std::uint32_t v) {
  regs[address] = static_cast<std::uint16_t>(v >> 16);  // high word first: see register_map.hpp
  regs[address + 1] = static_cast<std::uint16_t>(v & 0xFFFFu);
}

void put_float(std::uint16_t* regs, int address, const sim::SensorReading& r) {
  const float v = r.connected ? static_cast<float>(r.value) : std::numeric_limits<float>::quiet_NaN();
  put_u32(regs, address, std::bit_cast<std::uint32_t>(v));
}

void put_float(std::uint16_t* regs, int address, double value) {
  put_u32(regs, address, std::bit_cast<std::uint32_t>(static_cast<float>(value)));
}

void put_i32(std::uint16_t* regs, int address, const sim::SensorReading& r, double counts_per_unit) {
  double counts = r.connected ? std::nearbyint(r.value * counts_per_unit) : 0.0;
  counts = std::clamp(counts, -2147483648.0, 2147483647.0);
  put_u32(regs, address, static_cast<std::uint32_t>(static_cast<std::int32_t>(counts)));
}

float get_float(const std::uint16_t* regs, int address) {
  return std::bit_cast<float>(static_cast<std::uint32_t>(regs[address]) << 16 | regs[address + 1]);
}

void put_safe_valve(_modbus_mapping_t* map) {
  put_float(map->tab_registers, holding_register::valve_command, 0.0);
  map->tab_bits[coil::valve_enable] = 0;
}

// What a request (the PDU: function code first) writes. libmodbus has already checked the frame;
// a request too short to hold an address counts as a write, not an output write.
struct RequestWrites {
  bool any = false;           // a write function code
  bool outputs = false;       // the valve command registers or the enable coil: the master's alone
  bool command = false;       // the valve command registers among them
  bool enable = false;        // the enable coil among them
};

RequestWrites classify(const std::uint8_t* pdu, int length) {
  RequestWrites w;
  if (length < 1) return w;
  const auto u16 = [&](int i) { return static_cast<int>(pdu[i]) << 8 | pdu[i + 1]; };
  // Whether [first, first + count) holds any of [lo, lo + n).
  const auto overlaps = [](int first, int count, int lo, int n) { return first < lo + n && lo < first + count; };
  constexpr int command_first = holding_register::valve_command;
  constexpr int command_words = 2;
  switch (pdu[0]) {
    case MODBUS_FC_WRITE_SINGLE_COIL:
      w.any = true;
      w.enable = length >= 3 && u16(1) == coil::valve_enable;
      break;
    case MODBUS_FC_WRITE_MULTIPLE_COILS:
      w.any = true;
      w.enable = length >= 5 && overlaps(u16(1), u16(3), coil::valve_enable, 1);
      break;
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_MASK_WRITE_REGISTER:
      w.any = true;
      w.command = length >= 3 && overlaps(u16(1), 1, command_first, command_words);
      break;
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
      w.any = true;
      w.command = length >= 5 && overlaps(u16(1), u16(3), command_first, command_words);
      break;
    case MODBUS_FC_WRITE_AND_READ_REGISTERS:  // read address, count, then write address, count
      w.any = true;
      w.command = length >= 9 && overlaps(u16(5), u16(7), command_first, command_words);
      break;
    default:
      break;
  }
  w.outputs = w.command || w.enable;
  return w;
}

}  // namespace

ModbusServer::ModbusServer(RigRunner& rig, int port, bool proportional_valve, int watchdog_ms)
    : rig_(rig), proportional_(proportional_valve), watchdog_ms_(watchdog_ms) {
  ctx_ = modbus_new_tcp("127.0.0.1", port);
  if (ctx_ == nullptr) throw std::runtime_error(std::string("modbus_new_tcp: ") + modbus_strerror(errno));
  map_ = modbus_mapping_new(coil::count, discrete_input::count, holding_register::count,
                            input_register::count);
  if (map_ == nullptr) {
    modbus_free(ctx_);
    throw std::runtime_error(std::string("modbus_mapping_new: ") + modbus_strerror(errno));
  }
  listen_fd_ = modbus_tcp_listen(ctx_, 8);
  if (listen_fd_ < 0) {
    const std::string reason = modbus_strerror(errno);
    modbus_mapping_free(map_);
    modbus_free(ctx_);
    throw std::runtime_error("cannot listen on 127.0.0.1:" + std::to_string(port) + ": " + reason);
  }
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  refresh_inputs();
}

ModbusServer::~ModbusServer() {
  if (listen_fd_ >= 0) close(listen_fd_);
  modbus_mapping_free(map_);
  // No modbus_close: the context's socket is whichever client was served last, closed already.
  modbus_free(ctx_);
}

void ModbusServer::refresh_inputs() {
  const RigOutputs out = rig_.outputs();
  const sim::RigReadings& r = out.readings;
  std::uint16_t* ir = map_->tab_input_registers;
  put_float(ir, input_register::position_m, r.encoder_m);
  put_float(ir, input_register::pressure_a_pa, r.pressure_a_pa);
  put_float(ir, input_register::pressure_b_pa, r.pressure_b_pa);
  // A servo-valve has its own electronics: the rig has no spool or current sensor to serve.
  put_float(ir, input_register::spool_lvdt_m, proportional_ ? r.spool_lvdt_m : sim::SensorReading{0.0, true});
  put_float(ir, input_register::valve_current_a, proportional_ ? r.valve_current_a : sim::SensorReading{0.0, true});
  put_float(ir, input_register::time_s, out.time_s);
  put_i32(ir, input_register::position_um_i32, r.encoder_m, 1e6);
  put_i32(ir, input_register::pressure_a_pa_i32, r.pressure_a_pa, 1.0);
  put_i32(ir, input_register::pressure_b_pa_i32, r.pressure_b_pa, 1.0);
  ir[input_register::sensor_bits] = static_cast<std::uint16_t>(
      (r.encoder_m.connected ? 1 : 0) | (r.pressure_a_pa.connected ? 2 : 0) |
      (r.pressure_b_pa.connected ? 4 : 0) | (proportional_ && r.spool_lvdt_m.connected ? 8 : 0) |
      (proportional_ && r.valve_current_a.connected ? 16 : 0));
  map_->tab_input_bits[discrete_input::estop_loop_closed] = r.estop_pressed ? 0 : 1;
  const WatchdogState wd = rig_.watchdog();
  ir[input_register::watchdog_tripped] = wd.tripped ? 1 : 0;
  ir[input_register::watchdog_trips] = static_cast<std::uint16_t>(wd.trips & 0xFFFFu);
  ir[input_register::watchdog_ms] = static_cast<std::uint16_t>(watchdog_ms_);
  ir[input_register::foreign_writes] = static_cast<std::uint16_t>(foreign_writes_ & 0xFFFFu);
  ir[input_register::valve_power_cut] = rig_.valve_power_cut() ? 1 : 0;
  ir[input_register::refused_command_writes] = static_cast<std::uint16_t>(refused_command_writes_ & 0xFFFFu);
  map_->tab_input_bits[discrete_input::watchdog_tripped] = wd.tripped ? 1 : 0;
  // The rig's thread tripped it between requests: the valve outputs read back as they are.
  if (wd.tripped) put_safe_valve(map_);
}

void ModbusServer::apply_outputs(const MasterWrite& write) {
  RigInputs in;
  const float command = get_float(map_->tab_registers, holding_register::valve_command);
  in.valve_command = std::isfinite(command) ? command : 0.0;  // garbage in: valve to rest
  in.valve_enable = map_->tab_bits[coil::valve_enable] != 0;
  in.estop_pressed = map_->tab_bits[coil::estop_button] != 0;
  const RigInputs held = rig_.set_inputs(in, write);
  if (held.valve_command != in.valve_command || held.valve_enable != in.valve_enable) put_safe_valve(map_);
}

void ModbusServer::serve(const std::atomic<bool>& stop, std::chrono::steady_clock::time_point until) {
  std::vector<int> clients;
  std::vector<std::uint8_t> query(MODBUS_TCP_MAX_ADU_LENGTH);
  while (!stop.load() && std::chrono::steady_clock::now() < until) {
    fd_set readable;
    FD_ZERO(&readable);
    FD_SET(listen_fd_, &readable);
    int max_fd = listen_fd_;
    for (const int fd : clients) {
      FD_SET(fd, &readable);
      max_fd = std::max(max_fd, fd);
    }
    timeval timeout{0, 50'000};  // wakes up to check stop and --duration
    const int n = select(max_fd + 1, &readable, nullptr, nullptr, &timeout);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(std::string("select: ") + modbus_strerror(errno));
    }
    if (n == 0) continue;
    if (FD_ISSET(listen_fd_, &readable) && clients.size() < FD_SETSIZE / 2) {
      const int fd = accept(listen_fd_, nullptr, nullptr);
      if (fd >= 0 && fd < FD_SETSIZE) {
        clients.push_back(fd);
      } else if (fd >= 0) {
        close(fd);
      }
    }
    for (auto it = clients.begin(); it != clients.end();) {
      if (!FD_ISSET(*it, &readable)) {
        ++it;
        continue;
      }
      modbus_set_socket(ctx_, *it);
      const int rc = modbus_receive(ctx_, query.data());
      if (rc > 0) {
        serve_request(*it, query.data(), rc, io::monotonic_ns());
        ++it;
      } else if (rc == 0) {
        ++it;  // a frame for another unit, ignored
      } else {
        if (*it == master_fd_) master_fd_ = -1;  // the next connection to write an output is the master
        close(*it);  // closed by the client, or garbage: drop it
        it = clients.erase(it);
      }
    }
  }
  for (const int fd : clients) close(fd);
  master_fd_ = -1;
}

void ModbusServer::serve_request(int fd, const std::uint8_t* query, int length, std::int64_t received_ns) {
  const int header = modbus_get_header_length(ctx_);
  const RequestWrites writes = classify(query + header, length - header);
  ++requests_;
  if (writes.outputs && master_fd_ < 0) master_fd_ = fd;
  if (writes.outputs && fd != master_fd_) {
    ++foreign_writes_;
    modbus_reply_exception(ctx_, query, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
    return;
  }
  // The test hook of coil 9 (register_map.hpp): refused before the reply, so the mapping keeps the
  // last accepted command, and before apply_outputs, so the refusal feeds no watchdog.
  if (writes.command && map_->tab_bits[coil::refuse_valve_command] != 0) {
    ++refused_command_writes_;
    modbus_reply_exception(ctx_, query, MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE);
    return;
  }
  refresh_inputs();
  modbus_reply(ctx_, query, length, map_);
  // Only the master's writes feed the watchdog and reset what it latched; another connection's
  // write (the heartbeat register, the e-stop button) is applied but is no master write.
  const MasterWrite write = fd == master_fd_ ? MasterWrite{writes.any, writes.enable} : MasterWrite{};
  apply_outputs(write);
  if (writes.command && fd == master_fd_) {
    rig_.note_valve_command(get_float(map_->tab_registers, holding_register::valve_command), received_ns);
  }
}

}  // namespace hsa::simdev
