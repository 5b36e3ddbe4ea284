// InstanceLock: a second holder of any resource is refused with the first one's pid, and every
// lock goes with its holder; the resources are the LCM group and port (not the URL's text) and the
// devices each plugin states, so two spellings of one network or device are one lock; held_resource
// finds a held one without taking it (instance_lock.hpp).
#include "daemon/hsad/instance_lock.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "daemon/config/load_config.hpp"

namespace hsa::daemon {
namespace {

class InstanceLockTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/hsa-lock-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    dir_ += "/run";  // not there yet: InstanceLock creates it
  }
  void TearDown() override { std::filesystem::remove_all(std::filesystem::path(dir_).parent_path()); }

  static DaemonConfig config(const std::string& source, const std::string& axis,
                             const std::string& lcm_url = "udpm://239.255.76.67:7667?ttl=0") {
    DaemonConfig c;
    c.source = source;
    c.lcm_url = lcm_url;
    c.axes.emplace_back();
    c.axes.back().name = axis;
    return c;
  }

  // A driver as a plugin would state it, opening `devices`.
  static std::vector<PlannedDriver> driver(const std::vector<std::string>& devices) {
    return {{"io", "modbus", {devices, {}}}};
  }

  // The message of the refusal `resources` meet while `held` holds, or "" if none.
  std::string refusal(const std::vector<LockedResource>& held, const std::vector<LockedResource>& resources) {
    const InstanceLock first(dir_, held);
    try {
      const InstanceLock second(dir_, resources);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  std::string dir_;
};

TEST_F(InstanceLockTest, ResourcesAreTheConfigurationEachAxisOnItsGroupAndPortAndEachDevice) {
  const auto r = resources_of(config("/tmp/a.toml", "x"), driver({"modbus-tcp:127.0.0.1:1502"}));
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].what, "configuration /tmp/a.toml");
  EXPECT_EQ(r[1].what, "axis x on LCM group 239.255.76.67 port 7667");
  EXPECT_EQ(r[2].what, "I/O modbus-tcp:127.0.0.1:1502 (driver 'io')");
  EXPECT_EQ(resources_of(config("/tmp/a.toml", "x"), driver({"can:can0", "can:can1"})).size(), 4u);
  EXPECT_EQ(resources_of(config("/tmp/a.toml", "x"), driver({})).size(), 2u) << "no device: no I/O lock";
}

TEST_F(InstanceLockTest, ASecondHsadOnTheSameConfigurationIsRefusedWithThePidOfTheFirst) {
  const auto r = resources_of(config("/tmp/a.toml", "x"), driver({"modbus-tcp:127.0.0.1:1502"}));
  const std::string why = refusal(r, r);
  EXPECT_NE(why.find("another hsad (pid " + std::to_string(getpid()) + ")"), std::string::npos) << why;
  EXPECT_NE(why.find("configuration /tmp/a.toml"), std::string::npos) << why;
  EXPECT_NE(why.find(dir_ + "/config-"), std::string::npos) << why;
}

TEST_F(InstanceLockTest, AnotherConfigurationOnTheSameAxisOrDeviceIsRefused) {
  const auto a = resources_of(config("/tmp/a.toml", "x"), driver({"modbus-tcp:127.0.0.1:1502"}));
  const std::string same_axis =
      refusal(a, resources_of(config("/tmp/b.toml", "x"), driver({"modbus-tcp:127.0.0.1:1503"})));
  EXPECT_NE(same_axis.find("drives axis x on LCM group 239.255.76.67 port 7667"), std::string::npos) << same_axis;
  const std::string same_device =
      refusal(a, resources_of(config("/tmp/b.toml", "y"), driver({"modbus-tcp:127.0.0.1:1502"})));
  EXPECT_NE(same_device.find("drives I/O modbus-tcp:127.0.0.1:1502"), std::string::npos) << same_device;
  EXPECT_EQ(refusal(a, resources_of(config("/tmp/b.toml", "y"), driver({"modbus-tcp:127.0.0.1:1503"}))), "")
      << "nothing shared: both may run";
}

TEST_F(InstanceLockTest, UrlsThatDifferOnlyInTheirOptionsAreOneNetwork) {
  const auto a = resources_of(config("/tmp/a.toml", "x", "udpm://239.255.76.67:7667?ttl=0"), {});
  for (const char* same : {"udpm://239.255.76.67:7667?ttl=1", "udpm://239.255.76.67?ttl=1&recv_buf_size=4096"}) {
    const std::string why = refusal(a, resources_of(config("/tmp/b.toml", "x", same), {}));
    EXPECT_NE(why.find("drives axis x on LCM group 239.255.76.67 port 7667"), std::string::npos) << same << ": " << why;
  }
  EXPECT_EQ(refusal(a, resources_of(config("/tmp/b.toml", "x", "udpm://239.255.76.67:7668?ttl=0"), {})), "")
      << "another port is another network";
  EXPECT_EQ(refusal(a, resources_of(config("/tmp/b.toml", "x", "udpm://239.255.76.68:7667?ttl=0"), {})), "")
      << "another group is another network";
}

// The modbus plugin's own statement: an omitted port is its default, 502, so both spellings lock
// one device.
TEST_F(InstanceLockTest, AModbusDeviceWithItsPortOmittedIsTheOneOnPort502) {
  std::ifstream in(std::string(HSA_SOURCE_DIR) + "/systemd/hsad-modbus-simdev.toml");
  std::stringstream text;
  text << in.rdbuf();
  DaemonConfig omitted = parse_config(text.str(), "a.toml");
  DaemonConfig explicit_502 = parse_config(text.str(), "b.toml");
  omitted.drivers.at(0).settings.erase("port");
  explicit_502.drivers.at(0).settings.insert_or_assign("port", 502);
  explicit_502.axes.at(0).name = "other";  // only the device is shared
  const DriverPlans a = plan_drivers(omitted), b = plan_drivers(explicit_502);
  ASSERT_TRUE(a.refused.empty() && b.refused.empty());
  const std::string why = refusal(resources_of(omitted, a.drivers), resources_of(explicit_502, b.drivers));
  EXPECT_NE(why.find("drives I/O modbus-tcp:127.0.0.1:502 (driver 'io')"), std::string::npos) << why;
}

TEST_F(InstanceLockTest, HeldResourceNamesAHeldOneAsTheLockWouldWithoutTakingIt) {
  const auto a = resources_of(config("/tmp/a.toml", "x"), driver({"can:can0"}));
  const auto b = resources_of(config("/tmp/b.toml", "y"), driver({"can:can0"}));
  EXPECT_EQ(held_resource(dir_, b), "") << "nothing locked yet";
  EXPECT_FALSE(std::filesystem::exists(dir_)) << "held_resource made the lock directory";
  {
    const InstanceLock first(dir_, a);
    const std::string held = held_resource(dir_, b);
    EXPECT_NE(held.find("another hsad (pid " + std::to_string(getpid()) + ") already drives I/O can:can0"),
              std::string::npos) << held;
    try {
      const InstanceLock second(dir_, b);
      ADD_FAILURE() << "the second lock was granted";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(held, e.what()) << "not the lock's own words";
    }
  }
  EXPECT_EQ(held_resource(dir_, b), "");
  EXPECT_NO_THROW(const InstanceLock second(dir_, b)) << "held_resource kept a lock";
}

TEST_F(InstanceLockTest, TheLocksGoWithTheirHolderAndARefusalKeepsNone) {
  const auto a = resources_of(config("/tmp/a.toml", "x"), {});
  const auto b = resources_of(config("/tmp/b.toml", "x"), {});  // only the axis is shared
  { const InstanceLock first(dir_, a); }
  EXPECT_NO_THROW(const InstanceLock again(dir_, a)) << "a lock outlived its holder";
  // b is refused on its axis after it locked its configuration; that lock must have gone with it
  // (a lock kept by this process would refuse the next open file of the same name).
  EXPECT_NE(refusal(a, b), "");
  EXPECT_NO_THROW(const InstanceLock b_config(dir_, {b[0]})) << "b's configuration lock was kept after its refusal";
}

TEST_F(InstanceLockTest, AnUnusableLockDirectoryIsRefusedWithItsPath) {
  const std::string file = std::filesystem::path(dir_).parent_path() / "plain-file";
  std::ofstream(file) << "x";
  try {
    const InstanceLock lock(file + "/run", resources_of(config("/tmp/a.toml", "x"), {}));
    FAIL() << "a lock directory under a plain file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file + "/run"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hsa::daemon
