// InstanceLock: a second holder of any resource is refused with the first one's pid, and every
// lock goes with its holder (instance_lock.hpp).
#include "daemon/hsad/instance_lock.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

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

  static DaemonConfig config(const std::string& source, const std::string& axis, const std::string& driver_settings) {
    DaemonConfig c;
    c.source = source;
    c.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
    c.axes.emplace_back();
    c.axes.back().name = axis;
    c.drivers.push_back({"io", "modbus", toml::parse(driver_settings)});
    return c;
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

TEST_F(InstanceLockTest, ResourcesAreTheConfigurationEachAxisAndEachDriverEndpoint) {
  const auto r = resources_of(config("/tmp/a.toml", "x", "host = '127.0.0.1'\nport = 1502\n"));
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].what, "configuration /tmp/a.toml");
  EXPECT_EQ(r[1].what, "axis x on udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(r[2].what, "I/O tcp:127.0.0.1:1502 (driver 'io')");
  EXPECT_EQ(resources_of(config("/tmp/a.toml", "x", "interface = 'can0'\n"))[2].what, "I/O can:can0 (driver 'io')");
  EXPECT_EQ(resources_of(config("/tmp/a.toml", "x", "seed = 1\n")).size(), 2u) << "no endpoint: no I/O lock";
}

TEST_F(InstanceLockTest, ASecondHsadOnTheSameConfigurationIsRefusedWithThePidOfTheFirst) {
  const auto r = resources_of(config("/tmp/a.toml", "x", "host = '127.0.0.1'\nport = 1502\n"));
  const std::string why = refusal(r, r);
  EXPECT_NE(why.find("another hsad (pid " + std::to_string(getpid()) + ")"), std::string::npos) << why;
  EXPECT_NE(why.find("configuration /tmp/a.toml"), std::string::npos) << why;
  EXPECT_NE(why.find(dir_ + "/config-"), std::string::npos) << why;
}

TEST_F(InstanceLockTest, AnotherConfigurationOnTheSameAxisOrDeviceIsRefused) {
  const auto a = resources_of(config("/tmp/a.toml", "x", "host = '127.0.0.1'\nport = 1502\n"));
  const std::string same_axis = refusal(a, resources_of(config("/tmp/b.toml", "x", "host = '127.0.0.1'\nport = 1503\n")));
  EXPECT_NE(same_axis.find("drives axis x on udpm://"), std::string::npos) << same_axis;
  const std::string same_device =
      refusal(a, resources_of(config("/tmp/b.toml", "y", "host = '127.0.0.1'\nport = 1502\n")));
  EXPECT_NE(same_device.find("drives I/O tcp:127.0.0.1:1502"), std::string::npos) << same_device;
  EXPECT_EQ(refusal(a, resources_of(config("/tmp/b.toml", "y", "host = '127.0.0.1'\nport = 1503\n"))), "")
      << "nothing shared: both may run";
}

TEST_F(InstanceLockTest, TheLocksGoWithTheirHolderAndARefusalKeepsNone) {
  const auto a = resources_of(config("/tmp/a.toml", "x", "seed = 1\n"));
  const auto b = resources_of(config("/tmp/b.toml", "x", "seed = 1\n"));  // only the axis is shared
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
    const InstanceLock lock(file + "/run", resources_of(config("/tmp/a.toml", "x", "seed = 1\n")));
    FAIL() << "a lock directory under a plain file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file + "/run"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hsa::daemon
