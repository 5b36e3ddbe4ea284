// A plain libmodbus TCP client on 127.0.0.1: the raw view of a Modbus server, beside the plugin
// under test or benchmark, with no scaling, no bus thread and no retries.
#pragma once

#include <modbus/modbus.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace hsa::io::modbus_test {

class ModbusRawClient {
 public:
  ModbusRawClient(int port, std::chrono::microseconds response_timeout)
      : ctx_(modbus_new_tcp("127.0.0.1", port)) {
    if (ctx_ == nullptr) throw std::runtime_error("modbus_new_tcp failed");
    const auto us = response_timeout.count();
    modbus_set_response_timeout(ctx_, static_cast<std::uint32_t>(us / 1'000'000),
                                static_cast<std::uint32_t>(us % 1'000'000));
    connected_ = modbus_connect(ctx_) == 0;
  }
  ~ModbusRawClient() {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  ModbusRawClient(const ModbusRawClient&) = delete;
  ModbusRawClient& operator=(const ModbusRawClient&) = delete;

  [[nodiscard]] bool connected() const { return connected_; }
  modbus_t* get() { return ctx_; }

  // The holding registers [address, address + count), or empty when the read failed.
  std::vector<std::uint16_t> registers(int address, int count) {
    std::vector<std::uint16_t> r(static_cast<std::size_t>(count), 0xDEAD);
    if (modbus_read_registers(ctx_, address, count, r.data()) != count) r.clear();
    return r;
  }
  // The coils [address, address + count), or empty when the read failed.
  std::vector<std::uint8_t> coils(int address, int count) {
    std::vector<std::uint8_t> r(static_cast<std::size_t>(count), 0xFF);
    if (modbus_read_bits(ctx_, address, count, r.data()) != count) r.clear();
    return r;
  }

 private:
  modbus_t* ctx_;
  bool connected_ = false;
};

}  // namespace hsa::io::modbus_test
