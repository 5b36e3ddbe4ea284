// Test fixture plugin "fixture_configure_fails": loads fine, then refuses every configuration,
// the way a driver does when its device is absent.
#include "drivers/driver.hpp"
#include "drivers/plugin_abi.hpp"

namespace {

using namespace hsa::io;

class ConfigureFailsDriver final : public Driver {
 public:
  // Its settings are fine; it is the device that refuses.
  Result check_settings(const toml::table&) const override { return Result::success(); }
  Result plan(const toml::table&, DriverPlan& plan) const override {
    plan = {{"fixture:/dev/fixture0"}, {}};
    return Result::success();
  }

  Result on_configure(const toml::table&) override {
    return Result::failure("cannot open /dev/fixture0: no such device");
  }
  std::span<const ChannelInfo> channels() const override { return {}; }
  IoStatus read(Timestamp, Duration, std::span<ChannelSlot>) noexcept override {
    return IoStatus::error;
  }
  IoStatus write(Timestamp, Duration, std::span<const ChannelSlot>) noexcept override {
    return IoStatus::error;
  }
  void make_safe() noexcept override {}  // never configured: no outputs to make safe
};

}  // namespace

HSA_DRIVER_PLUGIN("fixture_configure_fails", ConfigureFailsDriver)
