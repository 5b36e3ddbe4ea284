// Test fixture plugin "fixture_loopback": a driver with one channel of every kind whose inputs
// echo its outputs, so a test can follow a value from a bound output signal through write(),
// the plugin and read() back to a bound input signal.
//
//   channels   enc (encoder input, count: read() counts), ai (analog input, V: echoes ao),
//              ao (analog output, V), di (digital input: echoes do), do (digital output)
//   settings   fail_read_after = N   read() returns error from the (N+1)-th call on
//   make_safe  sets the outputs' echoes to 0 (their safe value) and counts the call in
//              fixture_loopback_make_safe_calls(), exported so a test can assert it was called
//              even when the driver is in error and its read() no longer runs
#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "drivers/driver.hpp"
#include "drivers/plugin_abi.hpp"
#include "drivers/table_reader.hpp"

namespace {

using namespace hsa::io;

std::atomic<std::uint64_t> g_make_safe_calls{0};

class LoopbackDriver final : public Driver {
 public:
  enum Channel : std::size_t { enc, ai, ao, di, do_, count };

  Result check_settings(const toml::table& table) const override {
    return Result::of([&] {
      const TableReader settings = TableReader::of(table);
      settings.reject_unknown_keys({"fail_read_after"});
      (void)settings.integer("fail_read_after", -1, std::numeric_limits<std::int64_t>::max(), -1);
    });
  }

  Result plan(const toml::table& table, DriverPlan& plan) const override {
    LoopbackDriver scratch;
    Result r = scratch.on_configure(table);
    if (r) plan = {{}, scratch.channels_};
    return r;
  }

  Result on_configure(const toml::table& table) override {
    try {
      const TableReader settings = TableReader::of(table);
      settings.reject_unknown_keys({"fail_read_after"});
      fail_read_after_ = settings.integer("fail_read_after", -1, std::numeric_limits<std::int64_t>::max(), -1);
    } catch (const ConfigError& e) {
      return Result::failure(e.what());
    }
    channels_ = {
        {"enc", ChannelKind::encoder_input, "count"},
        {"ai", ChannelKind::analog_input, "V"},
        {"ao", ChannelKind::analog_output, "V"},
        {"di", ChannelKind::digital_input, "1"},
        {"do", ChannelKind::digital_output, "1"},
    };
    reads_ = 0;
    return Result::success();
  }

  std::span<const ChannelInfo> channels() const override { return channels_; }

  Result on_cleanup() override {
    channels_.clear();
    return Result::success();
  }

  IoStatus read(Timestamp t, Duration, std::span<ChannelSlot> slots) noexcept override {
    if (fail_read_after_ >= 0 && reads_ >= fail_read_after_) return IoStatus::error;
    ++reads_;
    slots[enc] = {static_cast<double>(reads_), t, SampleStatus::ok};
    slots[ai] = {echo_ao_, t, SampleStatus::ok};
    slots[di] = {echo_do_, t, SampleStatus::ok};
    return IoStatus::ok;
  }

  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot> slots) noexcept override {
    echo_ao_ = slots[ao].value;
    echo_do_ = slots[do_].value;
    return IoStatus::ok;
  }

  void make_safe() noexcept override {
    echo_ao_ = 0.0;
    echo_do_ = 0.0;
    g_make_safe_calls.fetch_add(1, std::memory_order_relaxed);
  }

  std::string_view failure_reason() const noexcept override { return "fixture read failure injected"; }

 private:
  std::vector<ChannelInfo> channels_;
  std::int64_t fail_read_after_ = -1;
  std::int64_t reads_ = 0;
  double echo_ao_ = 0.0;
  double echo_do_ = 0.0;
};

}  // namespace

HSA_DRIVER_PLUGIN("fixture_loopback", LoopbackDriver)

// How many times make_safe ran in this process, over every driver of this plugin.
extern "C" __attribute__((visibility("default"))) std::uint64_t fixture_loopback_make_safe_calls() {
  return g_make_safe_calls.load(std::memory_order_relaxed);
}
