// The outcome of a driver's lifecycle step (configure, activate, ...): success, or a failure with a
// message for the operator.
//
// Lifecycle steps return this instead of throwing, because they are called across the plugin
// boundary and because a failed step is an expected event the daemon must report, not a bug.
// The cyclic read/write do not use it: they return IoStatus, which carries no string and so never
// allocates.
#pragma once

#include <exception>
#include <string>
#include <utility>

namespace hsa::io {

class [[nodiscard]] Result {
 public:
  static Result success() { return Result{true, {}}; }
  static Result failure(std::string message) { return Result{false, std::move(message)}; }
  // Runs `step`: success, or a failure with the message of what it threw (a ConfigError names
  // its key). For the lifecycle steps that parse, which must not throw across the plugin boundary.
  template <class Step>
  static Result of(Step&& step) {
    try {
      step();
      return success();
    } catch (const std::exception& e) {
      return failure(e.what());
    }
  }

  [[nodiscard]] bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  [[nodiscard]] const std::string& message() const { return message_; }

 private:
  Result(bool ok, std::string message) : ok_(ok), message_(std::move(message)) {}
  bool ok_;
  std::string message_;
};

// What read() and write() return every cycle. write_error: an earlier write failed, found by this
// call; a driver whose writes complete on its own thread (Modbus) learns of a refused write later
// and reports it at its next read, so the fault trips in that cycle and is still named a write's.
enum class IoStatus : unsigned char { ok, error, write_error };

}  // namespace hsa::io
