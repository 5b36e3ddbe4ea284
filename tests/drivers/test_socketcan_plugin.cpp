// The socketcan plugin as the daemon loads it: its settings errors come back from on_configure,
// and on a kernel without CAN (socket(PF_CAN) fails with EAFNOSUPPORT, as on this project's build
// machine) on_configure says so and names the modules needed. On a kernel with CAN that test
// skips; test_socketcan_vcan.cpp covers the real socket there.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <string>

#include <toml++/toml.h>

#include "drivers/plugin_error.hpp"
#include "drivers/plugin_loader.hpp"
#include "drivers/socketcan/can_socket.hpp"

namespace hsa::io::socketcan {
namespace {

using ::testing::HasSubstr;

const char* const valid_settings = R"(
interface = "vcan0"
[[frames]]
id = 0x181
direction = "input"
length = 4
[[frames.channels]]
name = "encoder"
kind = "encoder_input"
byte_offset = 0
bytes = 4
)";

// The message of the PluginError that configuring the plugin with `settings` throws.
std::string configure_error(const std::string& settings) {
  const PluginLoader loader({HSA_PLUGIN_DIR});
  try {
    (void)loader.load_driver("can", "socketcan", toml::parse(settings));
  } catch (const PluginError& e) {
    EXPECT_EQ(e.kind(), PluginErrorKind::configure_failed);
    return e.what();
  }
  return "(configured)";
}

// errno of socket(PF_CAN, SOCK_RAW, CAN_RAW), 0 when it worked.
int can_socket_errno() {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return errno;
  close(fd);
  return 0;
}

TEST(SocketCanPlugin, LoadsAndReportsConfigErrorsWithTheKey) {
  EXPECT_THAT(configure_error("interface = \"vcan0\"\n"), HasSubstr("frames: required key is missing"));
  std::string bad = valid_settings;
  bad.replace(bad.find("bytes = 4"), 9, "bytes = 6");
  EXPECT_THAT(configure_error(bad), HasSubstr("frames[0].channels[0].bytes: expected at most 4"));
}

TEST(SocketCanPlugin, ConfigureFailsClearlyWhenTheKernelHasNoCan) {
  if (can_socket_errno() != EAFNOSUPPORT) {
    GTEST_SKIP() << "this kernel supports AF_CAN; the real socket is tested by kernel_socketcan_vcan";
  }
  const std::string message = configure_error(valid_settings);
  EXPECT_THAT(message, HasSubstr("AF_CAN is not supported by this kernel"));
  EXPECT_THAT(message, HasSubstr("can and can-raw"));
  EXPECT_THAT(message, HasSubstr("can-dev"));
  EXPECT_THAT(message, HasSubstr("vcan"));
}

TEST(SocketCanPlugin, SocketFailureMessages) {
  EXPECT_THAT(socket_failure_message(EAFNOSUPPORT), HasSubstr("AF_CAN is not supported by this kernel"));
  EXPECT_THAT(socket_failure_message(EPROTONOSUPPORT), HasSubstr("kernel module can-raw"));
  EXPECT_THAT(socket_failure_message(EMFILE), HasSubstr("cannot open a raw CAN socket"));
}

}  // namespace
}  // namespace hsa::io::socketcan
