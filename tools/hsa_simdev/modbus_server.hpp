// hsa-simdev's Modbus TCP server: libmodbus in server mode on 127.0.0.1, serving the register
// map of register_map.hpp from a RigRunner.
//
// One thread multiplexes the listening socket and every client with select(), the pattern of
// libmodbus's own multi-client example, with a short timeout so it notices the stop request and
// the end of --duration. Before each reply the rig's latest readings are copied into the
// register mapping; after it, the valve command, enable and e-stop button written by the
// client are handed back to the rig, with what the request wrote, for the rig's communication
// watchdog; while it is tripped the valve command and enable in the mapping read back safe.
// The outputs belong to one connection, the master (register_map.hpp): the first to write one,
// until it closes. Another connection's writes to them are refused and counted, and nothing it
// writes feeds the watchdog. While the test hook of coil 9 is set, the master's writes to the
// valve command are refused too, with exception 03.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

#include "tools/hsa_simdev/rig_runner.hpp"

struct _modbus;
struct _modbus_mapping_t;

namespace hsa::simdev {

class ModbusServer {
 public:
  // Listens on 127.0.0.1:port (0: any free port, see port()). Throws std::runtime_error.
  // watchdog_ms: only shown in its input register; the rig runner holds the watchdog.
  ModbusServer(RigRunner& rig, int port, bool proportional_valve, int watchdog_ms = 0);
  ~ModbusServer();
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  [[nodiscard]] int port() const { return port_; }

  // Serves until `stop` is set or `until` passes (steady clock).
  void serve(const std::atomic<bool>& stop, std::chrono::steady_clock::time_point until);

  [[nodiscard]] std::uint64_t requests() const { return requests_; }

 private:
  void refresh_inputs();   // rig → mapping
  // received_ns: when the request had arrived whole (CLOCK_MONOTONIC), the time a valve command
  // it wrote is reported to the rig's delay probe with.
  void serve_request(int fd, const std::uint8_t* query, int length, std::int64_t received_ns);
  void apply_outputs(const MasterWrite& write);  // mapping → rig

  RigRunner& rig_;
  bool proportional_;  // else the spool LVDT and valve current registers read 0
  int watchdog_ms_;
  _modbus* ctx_ = nullptr;
  _modbus_mapping_t* map_ = nullptr;
  int listen_fd_ = -1;
  int port_ = 0;
  std::uint64_t requests_ = 0;
  int master_fd_ = -1;                 // the connection that owns the outputs; -1: none yet
  std::uint64_t foreign_writes_ = 0;  // output writes refused from other connections
  std::uint64_t refused_command_writes_ = 0;  // the master's, refused while coil 9 is set
};

}  // namespace hsa::simdev
