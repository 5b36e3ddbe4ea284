// hsa-simdev --can on a kernel without CAN: it refuses to start, exit status 1, with the same
// clear message as the socketcan plugin (they share the socket code). On a kernel with CAN this
// skips; kernel_socketcan_vcan closes a loop on hsa-simdev --can there.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <linux/can.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

namespace {

using ::testing::HasSubstr;

TEST(SocketCanSimdev, RefusesToStartWithoutCanAndSaysWhy) {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd >= 0) close(fd);
  if (fd >= 0 || errno != EAFNOSUPPORT) {
    GTEST_SKIP() << "this kernel supports AF_CAN; kernel_socketcan_vcan runs hsa-simdev --can";
  }
  // Bounded: it fails while starting up; timeout(1) guards against it serving instead.
  const std::string command = "timeout 10 " HSA_SIMDEV " --port 0 --duration 2 --can vcan0 2>&1";
  FILE* out = popen(command.c_str(), "r");
  ASSERT_NE(out, nullptr);
  std::string text;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, out) != nullptr) text += buffer;
  const int status = pclose(out);
  ASSERT_TRUE(WIFEXITED(status)) << text;
  EXPECT_EQ(WEXITSTATUS(status), 1) << text;
  EXPECT_THAT(text, HasSubstr("hsa-simdev: CAN: AF_CAN is not supported by this kernel"));
  EXPECT_THAT(text, HasSubstr("can-raw"));
}

}  // namespace
